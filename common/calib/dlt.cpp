#include "calib/dlt.h"

#include <Eigen/Dense>

#include <limits>
#include <vector>

#include "calib/eigen_glm.h"

namespace optique::calib {

std::optional<DltSolution> solve_dlt(std::span<const geometry::Correspondence> points) {
  if (points.size() < 4) return std::nullopt;
  std::vector<glm::dvec2> screen;
  std::vector<glm::dvec2> pixel;
  screen.reserve(points.size());
  pixel.reserve(points.size());
  for (const auto& c : points) {
    screen.push_back(c.screen);
    pixel.push_back(c.pixel);
  }
  const Eigen::Matrix3d ts = detail::hartley_transform(screen);
  const Eigen::Matrix3d tp = detail::hartley_transform(pixel);
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd a(2 * n, 9);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Eigen::Vector3d s = ts * Eigen::Vector3d(screen[k].x, screen[k].y, 1.0);
    const Eigen::Vector3d p = tp * Eigen::Vector3d(pixel[k].x, pixel[k].y, 1.0);
    a.row(2 * i) << 0, 0, 0, -s.x(), -s.y(), -1, p.y() * s.x(), p.y() * s.y(), p.y();
    a.row(2 * i + 1) << s.x(), s.y(), 1, 0, 0, 0, -p.x() * s.x(), -p.x() * s.y(), -p.x();
  }
  // With exactly 4 points the system is 8×9: the null vector needs the full V.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Eigen::Matrix3d normalized;
  normalized << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d full = tp.inverse() * normalized * ts;
  const double norm = full.norm();
  if (!full.allFinite() || norm == 0.0) return std::nullopt;
  full /= norm;

  DltSolution solution;
  solution.homography = detail::to_glm(full);
  const auto sv = svd.singularValues();
  solution.condition = sv(7) > 0.0 ? sv(0) / sv(7) : std::numeric_limits<double>::infinity();
  return solution;
}

}  // namespace optique::calib
