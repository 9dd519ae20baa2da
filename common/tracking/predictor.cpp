#include "tracking/predictor.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/geometric.hpp>

namespace optique::tracking {
namespace {

glm::dvec4 as_vector(const glm::dquat& q) { return {q.w, q.x, q.y, q.z}; }

glm::dquat as_quaternion(const glm::dvec4& v) {
  const double length = glm::length(v);
  if (!(length > 1e-12) || !std::isfinite(length)) return {1.0, 0.0, 0.0, 0.0};
  return glm::dquat(v.x / length, v.y / length, v.z / length, v.w / length);
}

// `q` or −q (the same turn), whichever lies in `near`'s hemisphere.
glm::dquat beside(const glm::dquat& q, const glm::dquat& near) { return glm::dot(q, near) < 0.0 ? -q : q; }

}  // namespace

HeadPredictor::HeadPredictor(config::HeadPrediction method, double smoothing) : method_(method), alpha_(smoothing) {
  assert(smoothing > 0.0 && smoothing < 1.0);
}

void HeadPredictor::reset() {
  samples_.clear();
  period_ = 0.0;
}

Nanos HeadPredictor::newest_time() const {
  assert(!samples_.empty());
  return samples_.back().time;
}

HeadPose HeadPredictor::newest() const {
  assert(!samples_.empty());
  return samples_.back().pose;
}

void HeadPredictor::add(Nanos time, const HeadPose& pose) {
  HeadPose p = pose;
  if (samples_.empty()) {
    s1_ = s2_ = p.position;
    q1_ = q2_ = as_vector(p.orientation);
  } else {
    assert(time - samples_.back().time >= kLeastSampleInterval);
    p.orientation = beside(p.orientation, samples_.back().pose.orientation);
    const double interval = static_cast<double>(time - samples_.back().time);
    period_ = period_ == 0.0 ? interval : 0.9 * period_ + 0.1 * interval;
    const double a = alpha_;
    s1_ = a * p.position + (1.0 - a) * s1_;
    s2_ = a * s1_ + (1.0 - a) * s2_;
    q1_ = a * as_vector(p.orientation) + (1.0 - a) * q1_;
    q2_ = a * q1_ + (1.0 - a) * q2_;
  }
  samples_.push_back({time, p});
  while (samples_.size() > static_cast<std::size_t>(kVelocitySpan) + 1) samples_.pop_front();
}

HeadPose HeadPredictor::predict(Nanos time) const {
  assert(!samples_.empty());
  HeadPose out = extrapolate(time);
  const HeadPose& last = samples_.back().pose;
  // Bounded by what a head can do, and finite whatever the samples were.
  const double ahead = static_cast<double>(std::clamp<Nanos>(time - samples_.back().time, 0, kMostPredictionAhead));
  const glm::dvec3 moved = out.position - last.position;
  const double most = kMostHeadSpeed * ahead / 1e9;
  const double length = glm::length(moved);
  if (!std::isfinite(length)) return last;
  if (length > most) out.position = last.position + moved * (most / length);
  const glm::dquat& q = out.orientation;
  if (!std::isfinite(q.w) || !std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
    out.orientation = last.orientation;
  }
  return out;
}

HeadPose HeadPredictor::extrapolate(Nanos time) const {
  assert(!samples_.empty());
  const Sample& last = samples_.back();
  const Nanos ahead = std::clamp<Nanos>(time - last.time, 0, kMostPredictionAhead);
  if (method_ == config::HeadPrediction::none || samples_.size() < 2 || ahead == 0) return last.pose;
  if (method_ == config::HeadPrediction::constant_velocity) {
    const Sample& first = samples_.front();
    const double span = static_cast<double>(last.time - first.time);
    const double f = static_cast<double>(ahead) / span;
    HeadPose out;
    out.position = last.pose.position + (last.pose.position - first.pose.position) * f;
    // The turn over the span (the short way round), carried on f times over.
    glm::dquat turn = last.pose.orientation * glm::inverse(first.pose.orientation);
    if (turn.w < 0.0) turn = -turn;
    const glm::dvec3 v{turn.x, turn.y, turn.z};
    const double sine = glm::length(v);
    const double angle = 2.0 * std::atan2(sine, turn.w);
    const glm::dquat more = sine > 1e-12 ? glm::angleAxis(angle * f, v / sine) : glm::dquat(1.0, 0.0, 0.0, 0.0);
    out.orientation = glm::normalize(more * last.pose.orientation);
    return out;
  }
  const double tau = static_cast<double>(ahead) / std::max(period_, static_cast<double>(kLeastSampleInterval));
  const double k = alpha_ * tau / (1.0 - alpha_);
  HeadPose out;
  out.position = (2.0 + k) * s1_ - (1.0 + k) * s2_;
  out.orientation = as_quaternion((2.0 + k) * q1_ - (1.0 + k) * q2_);
  return out;
}

}  // namespace optique::tracking
