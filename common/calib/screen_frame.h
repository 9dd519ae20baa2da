#pragma once
// The screen's own frame from tracker readings (DESIGN, "Tracker to screen
// frame"): a rigid transform tracker → screen that puts the screen plane at
// z = 0, the screen's x along the projector's pixel x and y up.

#include <span>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "calib/plane_fit.h"
#include "util/result.h"

namespace optique::calib {

// origin = the first reading projected on the plane; x = the direction of
// increasing pixel x on the plane (from a least-squares affine map pixels →
// plane, so it averages over all points rather than trusting two); z = the
// plane normal, signed so that y = z × x points towards decreasing pixel y
// (up on a front projector's image). Rows of the rotation are x, y, z.
// Fails when the pixels fix no such direction (all on one line).
[[nodiscard]] Result<glm::dmat4> derive_tracker_to_screen(std::span<const glm::dvec3> readings,
                                                          std::span<const glm::dvec2> pixels, const PlaneFit& plane);

// Fails, with the measured defect, unless `m` is finite, has bottom row
// [0 0 0 1] and an orthonormal, right-handed rotation (within 1e-6).
[[nodiscard]] Result<void> check_rigid(const glm::dmat4& m);

[[nodiscard]] glm::dvec3 transform_point(const glm::dmat4& m, const glm::dvec3& p);

}  // namespace optique::calib
