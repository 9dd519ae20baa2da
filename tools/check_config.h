#pragma once
// `optique-master check-config FILE`: the one-screen summary of a valid installation.

#include <string>

#include "config/load.h"

namespace optique::tools {

[[nodiscard]] std::string summarize(const config::LoadedConfig& config);

}  // namespace optique::tools
