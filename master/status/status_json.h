#pragma once
// The live status as /status.json and as each event of the page's stream.

#include <string>

#include "master/live_status.h"

namespace optique::master {

// One line of JSON (events are one line each); numbers without a value are null.
[[nodiscard]] std::string status_json(const LiveStatus& status);

}  // namespace optique::master
