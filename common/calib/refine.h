#pragma once
// Geometric refinement of a homography: Levenberg–Marquardt on the reprojection
// error in projector pixels, Σᵢ |H(screenᵢ) − pixelᵢ|², the maximum-likelihood
// estimate when the pixels carry Gaussian noise and the screen positions are
// exact (Hartley & Zisserman 4.2.2). The DLT minimizes an algebraic error that
// weights each point by its w, which costs accuracy on oblique projectors.

#include <span>

#include <glm/mat3x3.hpp>

#include "geometry/homography.h"

namespace optique::calib {

struct Refinement {
  glm::dmat3 homography{1.0};  // unit Frobenius norm
  int iterations = 0;
  double initial_rms_px = 0.0;
  double rms_px = 0.0;
};

// Starts from `initial` (e.g. the DLT). Works in Hartley-normalized coordinates
// with 8 parameters (the entry of the normalized H largest at the start stays
// fixed), so it is well conditioned for metres against 8K pixels and for any
// entry, h33 included, going to 0. Never returns a worse fit than `initial`.
[[nodiscard]] Refinement refine_homography(const glm::dmat3& initial, std::span<const geometry::Correspondence> points);

}  // namespace optique::calib
