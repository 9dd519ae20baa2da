#include "metrics/distribution.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace optique::metrics {

double percentile(std::vector<double>& values, double p) {
  assert(p >= 0.0 && p <= 100.0);
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  // Multiply before dividing, and forgive rounding, so p·n/100 that is an integer
  // stays that integer (p = 7, n = 100 → rank 7, not 8).
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()) / 100.0 - 1e-9));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

report::Distribution summarize(std::vector<double> values) {
  report::Distribution d;
  d.set_count(values.size());
  if (values.empty()) return d;
  d.set_median(percentile(values, 50.0));
  d.set_p99(percentile(values, 99.0));
  d.set_max(values.back());
  return d;
}

}  // namespace optique::metrics
