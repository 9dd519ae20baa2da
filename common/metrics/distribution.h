#pragma once
// Summaries for timing series: median, p99, max. Nearest-rank percentiles, so a
// reported value is always one that was measured.

#include <cstdint>
#include <vector>

#include "optique/report.pb.h"

namespace optique::metrics {

// Percentile p in [0, 100] of `values` (sorted in place). Empty → 0.
[[nodiscard]] double percentile(std::vector<double>& values, double p);

[[nodiscard]] report::Distribution summarize(std::vector<double> values);

// A series of unbounded length in bounded memory: every value counts towards
// count and max; median and p99 come from a uniform random sample of at most
// `capacity` values (reservoir sampling, fixed seed), so they are exact until the
// series outgrows the sample and close estimates after.
class Reservoir {
 public:
  explicit Reservoir(std::size_t capacity = 100'000) : capacity_(capacity) {}
  void add(double value);
  [[nodiscard]] report::Distribution summary() const;
  [[nodiscard]] std::uint64_t count() const { return count_; }

 private:
  std::size_t capacity_;
  std::vector<double> sample_;
  std::uint64_t count_ = 0;
  double max_ = 0.0;
  std::uint64_t random_state_ = 0x9E3779B97F4A7C15ull;
};

}  // namespace optique::metrics
