#pragma once
// Predicts a head (the eyes' centre and the head's orientation, world space)
// at a later time from the samples so far: what the master shows at a frame's
// display time, which lies a tracker latency and a frame or so after the newest
// sample.
// - none: the newest sample as it is.
// - constant-velocity: the newest sample moved on at the velocity (and angular
//   velocity) over the last kVelocitySpan samples.
// - double-exponential: LaViola's double exponential smoothing predictor
//   ("Double Exponential Smoothing: An Alternative to Kalman Filter-Based
//   Predictive Tracking", 2003): two exponentially smoothed series S and S²
//   (alpha = smoothing) and x(t + τ) = (2 + ατ/(1−α))·S − (1 + ατ/(1−α))·S², τ
//   in sample periods; orientations smoothed as quaternions in one hemisphere
//   and normalized, as the paper does.

#include <cstdint>
#include <deque>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "clock/clock.h"
#include "config/tracking.h"

namespace optique::tracking {

using clock::Nanos;

struct HeadPose {
  glm::dvec3 position{0.0};                    // the eyes' centre, metres
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0};  // head → world

  friend bool operator==(const HeadPose&, const HeadPose&) = default;
};

inline constexpr int kVelocitySpan = 3;  // constant-velocity: samples to take the velocity over
// Predictions are not made further ahead than this past the newest sample: a
// tracker that stalls without being lost yet does not send the head flying.
inline constexpr Nanos kMostPredictionAhead = 200'000'000;
// Samples closer than this are not taken (a tracker sends at most 300 a
// second): velocities stay those of motion, not of the stamps' noise.
inline constexpr Nanos kLeastSampleInterval = 1'000'000;
// No head moves faster than this (m/s): a prediction past it is cut short.
inline constexpr double kMostHeadSpeed = 10.0;

class HeadPredictor {
 public:
  HeadPredictor(config::HeadPrediction method, double smoothing);

  // A sample of `pose` at `time` (at least kLeastSampleInterval after the
  // previous one's).
  void add(Nanos time, const HeadPose& pose);
  [[nodiscard]] bool empty() const { return samples_.empty(); }
  [[nodiscard]] Nanos newest_time() const;  // !empty()
  [[nodiscard]] HeadPose newest() const;    // !empty()
  // The head at `time` (not before the newest sample: then the newest as it
  // is), at most kMostHeadSpeed away from the newest; always finite.
  [[nodiscard]] HeadPose predict(Nanos time) const;
  void reset();

 private:
  [[nodiscard]] HeadPose extrapolate(Nanos time) const;  // predict() before its bounds
  config::HeadPrediction method_;
  double alpha_;
  struct Sample {
    Nanos time;
    HeadPose pose;
  };
  std::deque<Sample> samples_;  // the newest kVelocitySpan + 1
  // Double exponential smoothing: S and S² of position and orientation (as a
  // 4-vector), and the mean sample period.
  glm::dvec3 s1_{0.0}, s2_{0.0};
  glm::dvec4 q1_{0.0}, q2_{0.0};
  double period_ = 0.0;  // nanoseconds, smoothed
};

}  // namespace optique::tracking
