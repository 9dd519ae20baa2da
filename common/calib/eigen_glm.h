#pragma once
// Internal to common/calib (needs Eigen, a private dependency of optique_common):
// conversions between glm's column-major dmat3 and Eigen, and Hartley's
// normalizing transform, which every solver here applies first so that
// metres and thousands of pixels meet at the same scale.

#include <Eigen/Core>

#include <cmath>
#include <span>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

namespace optique::calib::detail {

[[nodiscard]] inline Eigen::Matrix3d to_eigen(const glm::dmat3& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e(r, c) = m[c][r];
  }
  return e;
}

[[nodiscard]] inline glm::dmat3 to_glm(const Eigen::Matrix3d& e) {
  glm::dmat3 m(0.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[c][r] = e(r, c);
  }
  return m;
}

// Centroid to the origin, mean distance from it √2 (Hartley & Zisserman 4.4.4).
// A set whose points all coincide gets the translation only.
[[nodiscard]] inline Eigen::Matrix3d hartley_transform(std::span<const glm::dvec2> points) {
  glm::dvec2 centroid(0.0);
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  double mean_distance = 0.0;
  for (const auto& p : points) mean_distance += std::hypot(p.x - centroid.x, p.y - centroid.y);
  mean_distance /= static_cast<double>(points.size());
  const double s = mean_distance > 0.0 ? std::sqrt(2.0) / mean_distance : 1.0;
  Eigen::Matrix3d t;
  t << s, 0, -s * centroid.x, 0, s, -s * centroid.y, 0, 0, 1;
  return t;
}

}  // namespace optique::calib::detail
