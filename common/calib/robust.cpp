#include "calib/robust.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>

#include "calib/dlt.h"
#include "calib/point_checks.h"

namespace optique::calib {
namespace {

// A minimal sample this close to a line fixes H only through noise.
constexpr double kSampleLineRelative = 1e-3;
// An all-inlier sample is not always a good one (noise at its corners tilts H
// elsewhere): draw at least this many even when the first one convinces.
constexpr int kMinSamples = 10;

// The four sample points all on one side of the sample's horizon: a sample whose
// quadrilateral is twisted (a bow tie) on one side fits an H that flips
// orientation between them, which no projector does.
bool keeps_orientation(const glm::dmat3& h, std::span<const geometry::Correspondence> sample) {
  const double first = geometry::homogeneous_w(h, sample.front().screen);
  return std::all_of(sample.begin(), sample.end(), [&](const geometry::Correspondence& c) {
    return geometry::homogeneous_w(h, c.screen) * first > 0.0;
  });
}

// MSAC cost: inliers pay their squared error, others the squared threshold, so
// that among samples with as many inliers the tighter fit wins.
double msac_cost(const glm::dmat3& h, std::span<const geometry::Correspondence> points, double threshold) {
  double cost = 0.0;
  for (const auto& c : points) {
    const double e = geometry::reprojection_error(h, c);
    cost += std::isfinite(e) ? std::min(e * e, threshold * threshold) : threshold * threshold;
  }
  return cost;
}

// Samples needed to draw one all-inlier sample with probability `confidence`
// when a fraction `inlier_ratio` of the points are inliers.
int samples_needed(double inlier_ratio, double confidence, int cap) {
  const double all_inliers = std::pow(inlier_ratio, 4.0);
  if (all_inliers >= 1.0) return 1;
  if (all_inliers <= 0.0) return cap;
  const double n = std::log(1.0 - confidence) / std::log(1.0 - all_inliers);
  return n >= cap ? cap : std::max(1, static_cast<int>(std::ceil(n)));
}

}  // namespace

std::vector<std::size_t> inliers_of(const glm::dmat3& h, std::span<const geometry::Correspondence> points,
                                    double threshold_px) {
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (geometry::reprojection_error(h, points[i]) <= threshold_px) inliers.push_back(i);
  }
  return inliers;
}

Result<Consensus> find_consensus(std::span<const geometry::Correspondence> points, const RansacOptions& options) {
  if (points.size() < 4) {
    return Error{fmt::format("robust mode needs at least 4 correspondences (got {})", points.size())};
  }
  std::mt19937_64 random(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  Consensus best;
  double best_cost = std::numeric_limits<double>::infinity();
  int needed = options.max_samples;
  for (int s = 0; s < needed && s < options.max_samples; ++s) {
    ++best.samples;
    std::array<std::size_t, 4> index{};
    for (std::size_t k = 0; k < 4; ++k) {
      do {
        index[k] = pick(random);
      } while (std::find(index.begin(), index.begin() + static_cast<std::ptrdiff_t>(k), index[k]) !=
               index.begin() + static_cast<std::ptrdiff_t>(k));
    }
    std::array<geometry::Correspondence, 4> sample{};
    for (std::size_t k = 0; k < 4; ++k) sample[k] = points[index[k]];
    if (has_three_on_a_line(sample, kSampleLineRelative)) {
      ++best.degenerate_samples;
      continue;
    }
    const auto dlt = solve_dlt(sample);
    if (!dlt || !keeps_orientation(dlt->homography, sample)) {
      ++best.degenerate_samples;
      continue;
    }
    const double cost = msac_cost(dlt->homography, points, options.threshold_px);
    if (cost < best_cost) {
      best_cost = cost;
      best.homography = dlt->homography;
      best.inliers = inliers_of(dlt->homography, points, options.threshold_px);
      const double ratio = static_cast<double>(best.inliers.size()) / static_cast<double>(points.size());
      needed = std::max(kMinSamples, std::min(needed, samples_needed(ratio, options.confidence, options.max_samples)));
    }
  }
  if (!std::isfinite(best_cost)) {
    return Error{
        fmt::format("robust mode: all {} samples of 4 points were degenerate (three on a line or a twisted "
                    "quadrilateral): the points fix no homography",
                    best.samples)};
  }
  if (best.inliers.size() < 4) {
    return Error{
        fmt::format("robust mode: at most {} of {} points agree within {:.3g} px on any homography: too few "
                    "to fit one (check the points, or raise the threshold)",
                    best.inliers.size(), points.size(), options.threshold_px)};
  }
  return best;
}

}  // namespace optique::calib
