#pragma once
// How much depth precision the single-pass oblique projection of Raskar's
// method (Raskar's approximated depth, eq. 5 of "Immersive Planar Display using
// Roughly Aligned Projectors") leaves for this projector. The renderer draws with
// A = N_p · H · N_u⁻¹ (user NDC through R → projector NDC, a33 = 1) and scales
// depth by 1 − |a31| − |a32|: as |a31| + |a32| → 1 the depth range collapses.

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

#include "geometry/homography.h"
#include "util/result.h"

namespace optique::geometry {

struct ObliqueDepth {
  glm::dvec2 rect_min{0.0};  // R: the bounding rectangle of the image's corners on the screen
  glm::dvec2 rect_max{0.0};
  glm::dmat3 a{1.0};    // A = N_p · H · N_u⁻¹ with a33 = 1
  double factor = 0.0;  // |a31| + |a32|: the paper's depth scale is 1 − factor
  // The depth scale optique renders with (geometry::ObliqueProjection): bounded
  // over the lit quad, not all of R, so it stays positive where 1 − factor does not.
  double depth_scale = 0.0;
};

// At or above this the depth buffer keeps under a tenth of its range.
inline constexpr double kDepthFactorWarning = 0.9;

// N_u maps R to [−1, 1]²; N_p maps pixels to OpenGL NDC (y up, so flipped).
// Fails when the image's corners do not map to finite screen points or when
// a33 ≈ 0 (the centre of R on the projector's horizon).
[[nodiscard]] Result<ObliqueDepth> oblique_depth(const glm::dmat3& h, ImageSize image);

}  // namespace optique::geometry
