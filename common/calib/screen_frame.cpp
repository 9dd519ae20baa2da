#include "calib/screen_frame.h"

#include <fmt/format.h>
#include <Eigen/Dense>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace optique::calib {

Result<glm::dmat4> derive_tracker_to_screen(std::span<const glm::dvec3> readings, std::span<const glm::dvec2> pixels,
                                            const PlaneFit& plane) {
  const glm::dvec3 origin = readings.front() - glm::dot(readings.front() - plane.centroid, plane.normal) * plane.normal;
  // Least-squares affine map [px py 1] → in-plane (u, v): its first column is
  // where the plane goes per pixel of x, its second per pixel of y.
  const auto n = static_cast<Eigen::Index>(readings.size());
  Eigen::MatrixXd design(n, 3);
  Eigen::MatrixXd target(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const glm::dvec3 d = readings[k] - origin;
    design.row(i) << pixels[k].x, pixels[k].y, 1.0;
    target.row(i) << glm::dot(d, plane.axis_u), glm::dot(d, plane.axis_v);
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(design);
  if (qr.rank() < 3) return Error{"the pixels of the tracker points all lie on one line: they fix no screen x axis"};
  const Eigen::MatrixXd affine = qr.solve(target);  // 3×2
  const glm::dvec3 per_pixel_x = affine(0, 0) * plane.axis_u + affine(0, 1) * plane.axis_v;
  const glm::dvec3 per_pixel_y = affine(1, 0) * plane.axis_u + affine(1, 1) * plane.axis_v;
  if (!(glm::length(per_pixel_x) > 0.0)) return Error{"the tracker readings do not move with pixel x"};
  const glm::dvec3 x = glm::normalize(per_pixel_x);
  glm::dvec3 z = plane.normal;
  if (glm::dot(glm::cross(z, x), per_pixel_y) > 0.0) z = -z;
  const glm::dvec3 y = glm::cross(z, x);

  glm::dmat4 m(1.0);
  for (int c = 0; c < 3; ++c) {
    m[c][0] = x[c];
    m[c][1] = y[c];
    m[c][2] = z[c];
  }
  m[3][0] = -glm::dot(x, origin);
  m[3][1] = -glm::dot(y, origin);
  m[3][2] = -glm::dot(z, origin);
  return m;
}

Result<void> check_rigid(const glm::dmat4& m) {
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r])) return Error{"not finite"};
    }
  }
  if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) {
    return Error{fmt::format("the bottom row is [{} {} {} {}], not [0 0 0 1]", m[0][3], m[1][3], m[2][3], m[3][3])};
  }
  const glm::dmat3 rotation(m);
  const glm::dmat3 product = rotation * glm::transpose(rotation);
  double defect = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) defect = std::max(defect, std::abs(product[c][r] - (c == r ? 1.0 : 0.0)));
  }
  if (defect > 1e-6) {
    return Error{fmt::format(
        "the rotation is not orthonormal (R·Rᵀ is {:.3g} from the identity): not a rigid transform", defect)};
  }
  if (glm::determinant(rotation) < 0.0)
    return Error{"the rotation is a reflection (determinant −1), not a rigid transform"};
  return {};
}

glm::dvec3 transform_point(const glm::dmat4& m, const glm::dvec3& p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }

}  // namespace optique::calib
