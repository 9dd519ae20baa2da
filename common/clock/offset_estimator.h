#pragma once
// NTP-style clock offset from four timestamps. The node stamps t1 (send, its clock),
// the master t2 (receive) and t3 (send), the node t4 (receive). With symmetric
// paths, offset = ((t2 − t1) + (t3 − t4)) / 2 is what to add to the node's clock to
// get the master's; the error is at most half the round trip minus the master's
// hold time, so the sample with the lowest round trip is the most trustworthy.

#include <cstddef>
#include <deque>
#include <optional>

#include "clock/clock.h"

namespace optique::clock {

struct PingSample {
  Nanos t1 = 0;  // node: ping sent
  Nanos t2 = 0;  // master: ping received
  Nanos t3 = 0;  // master: pong sent
  Nanos t4 = 0;  // node: pong received
};

struct OffsetEstimate {
  Nanos offset = 0;  // master = node + offset
  Nanos round_trip = 0;
};

[[nodiscard]] OffsetEstimate estimate_from(const PingSample& sample);

// Keeps the last `window` samples and trusts the one with the lowest round trip.
class OffsetEstimator {
 public:
  explicit OffsetEstimator(std::size_t window = 16) : window_(window) {}

  // Returns false (and keeps nothing) for an impossible sample: negative round
  // trip or the master's hold time longer than the whole round trip.
  [[nodiscard]] bool add(const PingSample& sample);
  [[nodiscard]] std::optional<OffsetEstimate> best() const;
  [[nodiscard]] std::size_t size() const { return samples_.size(); }

 private:
  std::size_t window_;
  std::deque<OffsetEstimate> samples_;
};

}  // namespace optique::clock
