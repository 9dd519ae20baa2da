#pragma once
// Robust mode: RANSAC over minimal 4-point samples, so that a few gross
// mismatches (a misread pixel, a point clicked on the wrong mark) do not pull
// the whole fit. Seeded and deterministic: the same input gives the same result.

#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>

#include "geometry/homography.h"
#include "util/result.h"

namespace optique::calib {

struct RansacOptions {
  double threshold_px = 3.0;  // a point further than this from a sample's H votes against it
  std::uint64_t seed = 1;
  int max_samples = 2000;
  double confidence = 0.999;  // stop once a better consensus is this unlikely to be missed
};

struct Consensus {
  glm::dmat3 homography{1.0};        // the best sample's DLT, unit Frobenius norm
  std::vector<std::size_t> inliers;  // within the threshold of it, ascending
  int samples = 0;                   // drawn, degenerate ones included
  int degenerate_samples = 0;        // skipped: three on a line, or a sample that flips orientation
};

// Fails when no sample of 4 gives a usable H or fewer than 4 points agree with it.
[[nodiscard]] Result<Consensus> find_consensus(std::span<const geometry::Correspondence> points,
                                               const RansacOptions& options);

// Indices of the points within `threshold_px` of `homography`, ascending.
[[nodiscard]] std::vector<std::size_t> inliers_of(const glm::dmat3& homography,
                                                  std::span<const geometry::Correspondence> points,
                                                  double threshold_px);

}  // namespace optique::calib
