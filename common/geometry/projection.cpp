#include "geometry/projection.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace optique::geometry {

glm::dvec3 WorldRect::normal() const { return glm::normalize(glm::cross(right, up)); }

glm::dvec3 WorldRect::at(double u, double v) const { return lower_left + right * (u * width) + up * (v * height); }

Result<Frustum> off_axis_frustum(const WorldRect& rect, const glm::dvec3& eye, double near, double far) {
  if (!(std::isfinite(near) && std::isfinite(far) && near > 0.0 && far > near)) {
    return Error{"near and far must satisfy 0 < near < far (got " + std::to_string(near) + ", " + std::to_string(far) +
                 ")"};
  }
  if (!std::isfinite(eye.x) || !std::isfinite(eye.y) || !std::isfinite(eye.z)) {
    return Error{"the eye position is not finite"};
  }
  const glm::dvec3 n = rect.normal();
  const glm::dvec3 to_corner = rect.lower_left - eye;
  const double distance = -glm::dot(to_corner, n);  // eye to the rectangle's plane
  constexpr double kMinDistance = 1e-6;
  if (distance < kMinDistance) {
    return Error{"the eye is " + std::string(distance < 0 ? "behind" : "on") + " the screen plane (distance " +
                 std::to_string(distance) + " m): nothing can be seen through it"};
  }
  Frustum f;
  f.near = near;
  f.far = far;
  const double scale = near / distance;
  f.left = glm::dot(rect.right, to_corner) * scale;
  f.right = f.left + rect.width * scale;
  f.bottom = glm::dot(rect.up, to_corner) * scale;
  f.top = f.bottom + rect.height * scale;

  glm::dmat4 p(0.0);  // column-major: p[column][row]
  p[0][0] = 2.0 * near / (f.right - f.left);
  p[1][1] = 2.0 * near / (f.top - f.bottom);
  p[2][0] = (f.right + f.left) / (f.right - f.left);
  p[2][1] = (f.top + f.bottom) / (f.top - f.bottom);
  p[2][2] = -(far + near) / (far - near);
  p[2][3] = -1.0;
  p[3][2] = -2.0 * far * near / (far - near);
  f.projection = p;

  // Rows of the rotation are the rectangle's axes, so eye space is aligned with
  // the screen; then the eye moves to the origin.
  glm::dmat4 rotation(1.0);
  for (int i = 0; i < 3; ++i) {
    rotation[i][0] = rect.right[i];
    rotation[i][1] = rect.up[i];
    rotation[i][2] = n[i];
  }
  glm::dmat4 translation(1.0);
  translation[3] = glm::dvec4(-eye, 1.0);
  f.view = rotation * translation;
  return f;
}

glm::dvec3 eye_position(const glm::dvec3& centre, const glm::dvec3& head_right, double separation, Eye eye) {
  switch (eye) {
    case Eye::left:
      return centre - head_right * (0.5 * separation);
    case Eye::right:
      return centre + head_right * (0.5 * separation);
    case Eye::mono:
      break;
  }
  return centre;
}

}  // namespace optique::geometry
