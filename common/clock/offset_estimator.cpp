#include "clock/offset_estimator.h"

#include <algorithm>

namespace optique::clock {

OffsetEstimate estimate_from(const PingSample& s) {
  // Halve each difference before adding so the sum cannot overflow for clocks
  // that are far apart.
  const Nanos offset = (s.t2 - s.t1) / 2 + (s.t3 - s.t4) / 2;
  const Nanos round_trip = (s.t4 - s.t1) - (s.t3 - s.t2);
  return {offset, round_trip};
}

bool OffsetEstimator::add(const PingSample& sample) {
  if (sample.t4 < sample.t1 || sample.t3 < sample.t2) return false;
  const OffsetEstimate estimate = estimate_from(sample);
  if (estimate.round_trip < 0) return false;
  samples_.push_back(estimate);
  while (samples_.size() > window_) samples_.pop_front();
  return true;
}

std::optional<OffsetEstimate> OffsetEstimator::best() const {
  if (samples_.empty()) return std::nullopt;
  return *std::min_element(samples_.begin(), samples_.end(),
                           [](const auto& a, const auto& b) { return a.round_trip < b.round_trip; });
}

}  // namespace optique::clock
