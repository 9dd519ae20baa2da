#include "clock/offset_estimator.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace optique::clock {

namespace {

struct Line {
  double mean_x = 0.0;
  double mean_y = 0.0;
  double slope = 0.0;
};

template <typename Point, typename X, typename Y>
std::optional<Line> fit_line(const std::vector<Point>& points, X x_of, Y y_of) {
  constexpr double kFloor = 10'000.0;  // ns
  const auto weight = [](const Point& p) {
    const double sigma = static_cast<double>(p.estimate.round_trip) / 2.0 + kFloor;
    return 1.0 / (sigma * sigma);
  };
  double sum_w = 0.0;
  double sum_wx = 0.0;
  double sum_wy = 0.0;
  for (const Point& p : points) {
    const double w = weight(p);
    sum_w += w;
    sum_wx += w * x_of(p);
    sum_wy += w * y_of(p);
  }
  Line line;
  line.mean_x = sum_wx / sum_w;
  line.mean_y = sum_wy / sum_w;
  double sxx = 0.0;
  double sxy = 0.0;
  for (const Point& p : points) {
    const double w = weight(p);
    const double dx = x_of(p) - line.mean_x;
    sxx += w * dx * dx;
    sxy += w * dx * (y_of(p) - line.mean_y);
  }
  if (!(sxx > 0.0)) return std::nullopt;
  line.slope = sxy / sxx;
  return line;
}

// The points within max(3 robust standard deviations, 5 µs) of the line; the
// robust deviation is 1.4826 times the median absolute residual.
template <typename Point, typename X, typename Y>
std::vector<Point> without_outliers(const std::vector<Point>& points, const Line& line, X x_of, Y y_of) {
  std::vector<double> residuals;
  for (const Point& p : points) {
    residuals.push_back(std::abs(y_of(p) - (line.mean_y + line.slope * (x_of(p) - line.mean_x))));
  }
  std::vector<double> sorted = residuals;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double mad = sorted[sorted.size() / 2];
  const double limit = std::max(3.0 * 1.4826 * mad, 5'000.0);
  std::vector<Point> kept;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (residuals[i] <= limit) kept.push_back(points[i]);
  }
  return kept;
}

}  // namespace

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
  const auto x_of = [&](const Sample& p) { return static_cast<double>(p.node_time - origin); };
  const auto y_of = [&](const Sample& p) { return static_cast<double>(p.estimate.offset - quietest->offset); };
  const std::optional<Line> first = fit_line(points, x_of, y_of);
  if (!first) return result;
  // Then once more without the points far off that line: a bucket whose every
  // ping met a busy scheduler on one leg sits tens of µs off, and near the end
  // of the window it would tilt the line where it is read.
  const std::vector<Sample> kept = without_outliers(points, *first, x_of, y_of);
  const std::optional<Line> line = kept.size() >= 3 && kept.size() < points.size() ? fit_line(kept, x_of, y_of) : first;
  if (!line) return result;
  const double slope = line->slope;
  const double mean_x = line->mean_x;
  const double mean_y = line->mean_y;
  if (!std::isfinite(slope) || std::abs(slope) * 1e6 > settings_.max_drift_ppm) return result;
  const double offset = mean_y + slope * (static_cast<double>(node_time - origin) - mean_x);
  result.offset = quietest->offset + static_cast<Nanos>(std::llround(offset));
  result.drift_ppm = slope * 1e6;
  result.points = kept.size() >= 3 ? kept.size() : points.size();
  return result;
}

}  // namespace optique::clock
