#pragma once
// A benchmark cell: the median over repeated runs, with the min–max across runs as
// its error, e.g. "44 (43–48)".

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "metrics/distribution.h"

namespace optique::bench {

struct Spread {
  double median = 0.0;
  double low = 0.0;
  double high = 0.0;
};

[[nodiscard]] inline Spread spread(std::vector<double> values) {
  const auto [low, high] = std::minmax_element(values.begin(), values.end());
  const double min = *low;
  const double max = *high;
  return {metrics::percentile(values, 50.0), min, max};  // percentile sorts: read min and max first
}

// `decimals` digits after the point for all three numbers.
[[nodiscard]] inline std::string cell(const Spread& s, int decimals) {
  char text[96];
  std::snprintf(text, sizeof text, "%.*f (%.*f–%.*f)", decimals, s.median, decimals, s.low, decimals, s.high);
  return text;
}

}  // namespace optique::bench
