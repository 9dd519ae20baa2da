#pragma once
// The best-fit plane of 3D tracker readings taken on a screen: how flat the
// screen is as the tracker sees it, and the plane the screen frame lies in.

#include <span>

#include <glm/vec3.hpp>

#include "util/result.h"

namespace optique::calib {

struct PlaneFit {
  glm::dvec3 centroid{0.0};
  glm::dvec3 normal{0.0, 0.0, 1.0};  // unit; its sign is arbitrary (calib/screen_frame.h orients it)
  glm::dvec3 axis_u{1.0, 0.0, 0.0};  // unit, in the plane: the readings' main direction
  glm::dvec3 axis_v{0.0, 1.0, 0.0};  // unit, in the plane, ⟂ axis_u
  double rms_m = 0.0;                // distance of the readings from the plane
  double max_m = 0.0;
};

// Total least squares: the normal is the direction of least spread of the
// centred readings (their SVD). Fails on fewer than 3 readings, non-finite
// numbers, or readings all on one line (no plane through them is better than another).
[[nodiscard]] Result<PlaneFit> fit_plane(std::span<const glm::dvec3> readings);

}  // namespace optique::calib
