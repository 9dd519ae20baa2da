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

void Reservoir::add(double value) {
  max_ = count_ == 0 ? value : std::max(max_, value);
  ++count_;
  if (sample_.size() < capacity_) {
    sample_.push_back(value);
    return;
  }
  // splitmix64: deterministic, so the same run summarizes the same way.
  std::uint64_t z = (random_state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  const std::uint64_t slot = z % count_;
  if (slot < capacity_) sample_[slot] = value;
}

report::Distribution Reservoir::summary() const {
  report::Distribution d = summarize(sample_);
  d.set_count(count_);
  d.set_max(max_);
  return d;
}

}  // namespace optique::metrics
