#pragma once
// The direct linear transform (Hartley-normalized, SVD): H from four or more
// correspondences by minimizing the algebraic error. Fast and closed-form, the
// starting point for the geometric refinement (calib/refine.h) and the model
// of every RANSAC sample (calib/robust.h).

#include <optional>
#include <span>

#include <glm/mat3x3.hpp>

#include "geometry/homography.h"

namespace optique::calib {

struct DltSolution {
  glm::dmat3 homography{1.0};  // unit Frobenius norm; scale it as the caller needs
  double condition = 0.0;      // of the normalized system: σ_max / σ_8 (∞ when σ_8 = 0)
};

// Does not validate the points (calib/point_checks.h does); nullopt when fewer
// than 4 are given or the SVD gives non-finite numbers.
[[nodiscard]] std::optional<DltSolution> solve_dlt(std::span<const geometry::Correspondence> points);

}  // namespace optique::calib
