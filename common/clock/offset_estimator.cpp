#include "clock/offset_estimator.h"

#include <algorithm>
#include <cmath>
#include <vector>

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
  samples_.push_back({sample.t1 + (sample.t4 - sample.t1) / 2, estimate});
  while (samples_.size() > settings_.window) samples_.pop_front();
  return true;
}

std::optional<OffsetEstimate> OffsetEstimator::best() const {
  if (samples_.empty()) return std::nullopt;
  return std::min_element(
             samples_.begin(), samples_.end(),
             [](const Sample& a, const Sample& b) { return a.estimate.round_trip < b.estimate.round_trip; })
      ->estimate;
}

std::optional<ClockEstimate> OffsetEstimator::at(Nanos node_time) const {
  const std::optional<OffsetEstimate> quietest = best();
  if (!quietest) return std::nullopt;
  ClockEstimate result;
  result.offset = quietest->offset;
  result.round_trip = quietest->round_trip;
  result.error_bound = quietest->round_trip / 2;
  result.points = 1;

  // The quietest sample of each bucket: a burst of pings counts once, and a
  // bucket whose pings all met a busy scheduler still lets the line through
  // its best.
  std::vector<Sample> points;
  const Nanos origin = samples_.front().node_time;
  for (const Sample& s : samples_) {
    const Nanos bucket = (s.node_time - origin) / settings_.bucket;
    if (!points.empty() && (points.back().node_time - origin) / settings_.bucket == bucket) {
      if (s.estimate.round_trip < points.back().estimate.round_trip) points.back() = s;
    } else {
      points.push_back(s);
    }
  }
  if (points.size() < 3 || points.back().node_time - points.front().node_time < settings_.min_drift_span) {
    return result;
  }

  // Weighted least squares, each point by 1/σ² with σ its error bound (half its
  // round trip; a floor so a lucky zero does not take all the weight). Times
  // relative to the first point keep the doubles exact to the nanosecond.
  constexpr double kFloor = 10'000.0;  // ns
  double sum_w = 0.0;
  double sum_wx = 0.0;
  double sum_wy = 0.0;
  for (const Sample& p : points) {
    const double sigma = static_cast<double>(p.estimate.round_trip) / 2.0 + kFloor;
    const double w = 1.0 / (sigma * sigma);
    sum_w += w;
    sum_wx += w * static_cast<double>(p.node_time - origin);
    sum_wy += w * static_cast<double>(p.estimate.offset - quietest->offset);
  }
  const double mean_x = sum_wx / sum_w;
  const double mean_y = sum_wy / sum_w;
  double sxx = 0.0;
  double sxy = 0.0;
  for (const Sample& p : points) {
    const double sigma = static_cast<double>(p.estimate.round_trip) / 2.0 + kFloor;
    const double w = 1.0 / (sigma * sigma);
    const double dx = static_cast<double>(p.node_time - origin) - mean_x;
    sxx += w * dx * dx;
    sxy += w * dx * (static_cast<double>(p.estimate.offset - quietest->offset) - mean_y);
  }
  if (!(sxx > 0.0)) return result;
  const double slope = sxy / sxx;
  if (!std::isfinite(slope) || std::abs(slope) * 1e6 > settings_.max_drift_ppm) return result;
  const double offset = mean_y + slope * (static_cast<double>(node_time - origin) - mean_x);
  result.offset = quietest->offset + static_cast<Nanos>(std::llround(offset));
  result.drift_ppm = slope * 1e6;
  result.points = points.size();
  return result;
}

}  // namespace optique::clock
