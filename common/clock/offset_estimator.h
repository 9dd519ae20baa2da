#pragma once
// NTP-style clock offset and drift from four timestamps. The node stamps t1 (send,
// its clock), the master t2 (receive) and t3 (send), the node t4 (receive). With
// symmetric paths, offset = ((t2 − t1) + (t3 − t4)) / 2 is what to add to the
// node's clock to get the master's; the error is at most half the round trip minus
// the master's hold time, so samples with low round trips are the trustworthy
// ones. Two quartz clocks also drift apart (tens of ppm; 200 ppm is 200 µs a
// second), so the estimator fits a line, offset(t) = a + b·t, through the
// quietest sample of each short time bucket, weighting each by its round trip.

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

// The master's clock as the node sees it, at one node time.
struct ClockEstimate {
  Nanos offset = 0;        // master = node + offset, at the time asked about
  double drift_ppm = 0.0;  // how fast the offset grows: the master's clock gains this on the node's
  Nanos round_trip = 0;    // the quietest sample's
  Nanos error_bound = 0;   // half the quietest round trip: what path asymmetry can hide
  std::size_t points = 0;  // bucket minima the line went through (1: no drift fitted)
};

class OffsetEstimator {
 public:
  struct Settings {
    std::size_t window = 256;                     // samples kept (pings come 40 a second: 6.4 s)
    Nanos bucket = 200 * kNanosPerMilli;          // one point per bucket: its lowest round trip
    Nanos min_drift_span = 500 * kNanosPerMilli;  // fit a drift only over at least this much time
    double max_drift_ppm = 1000.0;                // quartz is within ±100 ppm; beyond this the fit is noise
  };

  OffsetEstimator() : OffsetEstimator(Settings{}) {}
  explicit OffsetEstimator(std::size_t window) : OffsetEstimator(Settings{.window = window}) {}
  explicit OffsetEstimator(Settings settings) : settings_(settings) {}

  // Returns false (and keeps nothing) for an impossible sample: negative round
  // trip or the master's hold time longer than the whole round trip.
  [[nodiscard]] bool add(const PingSample& sample);
  // The sample with the lowest round trip in the window.
  [[nodiscard]] std::optional<OffsetEstimate> best() const;
  // The offset at node time `node_time`, drift included once the samples span
  // min_drift_span with three or more bucket points; before that the quietest
  // sample's offset.
  [[nodiscard]] std::optional<ClockEstimate> at(Nanos node_time) const;
  [[nodiscard]] std::size_t size() const { return samples_.size(); }

 private:
  struct Sample {
    Nanos node_time = 0;  // midpoint of t1 and t4: when the offset was measured
    OffsetEstimate estimate;
  };
  Settings settings_;
  std::deque<Sample> samples_;
};

}  // namespace optique::clock
