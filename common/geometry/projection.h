#pragma once
// Off-axis (asymmetric) perspective from an eye through a rectangle in space: the
// projector's region of its screen, for any screen orientation (walls, floor,
// ceiling). The rectangle is the image plane, so tiles that share an edge share it
// exactly in every projection, and a CAVE's walls meet without seams.

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <string>

#include "util/result.h"

namespace optique::geometry {

// A rectangle in world space: its lower-left corner and unit axes along its width
// and height; the viewer side is right × up.
struct WorldRect {
  glm::dvec3 lower_left{0.0};
  glm::dvec3 right{1.0, 0.0, 0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double width = 1.0;
  double height = 1.0;

  [[nodiscard]] glm::dvec3 normal() const;
  // The world point at (u, v) ∈ [0, 1]² of the rectangle (0, 0 = lower left).
  [[nodiscard]] glm::dvec3 at(double u, double v) const;
};

struct Frustum {
  glm::dmat4 view{1.0};        // world → eye space (the rectangle's axes)
  glm::dmat4 projection{1.0};  // glFrustum-like, OpenGL clip space (z in [−w, w])
  double left = 0, right = 0, bottom = 0, top = 0, near = 0, far = 0;  // at the near plane
};

// Fails when the eye is on or behind the rectangle's plane, or near/far are not
// 0 < near < far (finite).
[[nodiscard]] Result<Frustum> off_axis_frustum(const WorldRect& rect, const glm::dvec3& eye, double near, double far);

// Where one eye is: the centre of the eyes moved half the separation along
// `head_right` (left eye to −, right eye to +; mono stays at the centre).
enum class Eye { mono, left, right };
[[nodiscard]] glm::dvec3 eye_position(const glm::dvec3& centre, const glm::dvec3& head_right, double separation,
                                      Eye eye);

}  // namespace optique::geometry
