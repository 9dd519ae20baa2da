#pragma once
// The live status in Prometheus' text exposition format (version 0.0.4), for a
// site's Prometheus to scrape from /metrics. Names by its conventions: prefix
// optique_, base units in the name (seconds, hertz), counters ending in _total,
// one label per projector; quantiles of summaries over the recent frames, their
// _sum and _count over the whole run.

#include <string>

#include "master/live_status.h"

namespace optique::master {

inline constexpr const char* kMetricsContentType = "text/plain; version=0.0.4; charset=utf-8";

[[nodiscard]] std::string status_metrics(const LiveStatus& status);

}  // namespace optique::master
