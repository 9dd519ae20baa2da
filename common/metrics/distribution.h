#pragma once
// Summaries for timing series: median, p99, max. Nearest-rank percentiles, so a
// reported value is always one that was measured.

#include <vector>

#include "optique/report.pb.h"

namespace optique::metrics {

// Percentile p in [0, 100] of `values` (sorted in place). Empty → 0.
[[nodiscard]] double percentile(std::vector<double>& values, double p);

[[nodiscard]] report::Distribution summarize(std::vector<double> values);

}  // namespace optique::metrics
