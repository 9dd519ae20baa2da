#include "calib/plane_fit.h"

#include <fmt/format.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace optique::calib {

Result<PlaneFit> fit_plane(std::span<const glm::dvec3> readings) {
  if (readings.size() < 3) return Error{fmt::format("a plane needs at least 3 readings (got {})", readings.size())};
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const auto& p = readings[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return Error{fmt::format("points[{}] has a non-finite tracker coordinate ({}, {}, {})", i, p.x, p.y, p.z)};
    }
  }
  glm::dvec3 centroid(0.0);
  for (const auto& p : readings) centroid += p;
  centroid /= static_cast<double>(readings.size());
  Eigen::MatrixXd centred(static_cast<Eigen::Index>(readings.size()), 3);
  for (std::size_t i = 0; i < readings.size(); ++i) {
    const glm::dvec3 d = readings[i] - centroid;
    centred.row(static_cast<Eigen::Index>(i)) << d.x, d.y, d.z;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinV);
  const Eigen::Vector3d sv = svd.singularValues();
  if (!(sv(1) > 1e-9 * sv(0))) {
    return Error{
        fmt::format("the tracker readings all lie on one line (spread {:.3g} m across it, {:.3g} m along it): "
                    "they fix no plane",
                    sv(1) / std::sqrt(static_cast<double>(readings.size())),
                    sv(0) / std::sqrt(static_cast<double>(readings.size())))};
  }
  const Eigen::Matrix3d v = svd.matrixV();
  PlaneFit plane;
  plane.centroid = centroid;
  plane.axis_u = {v(0, 0), v(1, 0), v(2, 0)};
  plane.axis_v = {v(0, 1), v(1, 1), v(2, 1)};
  plane.normal = {v(0, 2), v(1, 2), v(2, 2)};
  double sum = 0.0;
  for (const auto& p : readings) {
    const double d = std::abs(glm::dot(p - centroid, plane.normal));
    sum += d * d;
    plane.max_m = std::max(plane.max_m, d);
  }
  plane.rms_m = std::sqrt(sum / static_cast<double>(readings.size()));
  return plane;
}

}  // namespace optique::calib
