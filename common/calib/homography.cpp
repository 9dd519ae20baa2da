#include "calib/homography.h"

#include <Eigen/Dense>

#include <cmath>

namespace optique::calib {
namespace {

// Hartley normalization: centroid to the origin, mean distance √2.
Eigen::Matrix3d normalizing_transform(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& v : p) centroid += v;
  centroid /= static_cast<double>(p.size());
  double mean_distance = 0.0;
  for (const auto& v : p) mean_distance += (v - centroid).norm();
  mean_distance /= static_cast<double>(p.size());
  const double s = std::sqrt(2.0) / mean_distance;
  Eigen::Matrix3d t;
  t << s, 0, -s * centroid.x(), 0, s, -s * centroid.y(), 0, 0, 1;
  return t;
}

// Whether all points lie (within a relative tolerance) on one line: the smaller
// singular value of the centred point cloud against the larger.
bool collinear(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& v : p) centroid += v;
  centroid /= static_cast<double>(p.size());
  Eigen::MatrixXd centred(p.size(), 2);
  for (std::size_t i = 0; i < p.size(); ++i) centred.row(static_cast<Eigen::Index>(i)) = (p[i] - centroid).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred);
  const auto sv = svd.singularValues();
  return sv(1) <= 1e-9 * sv(0);
}

}  // namespace

glm::dvec2 apply(const glm::dmat3& h, const glm::dvec2& screen) {
  const glm::dvec3 p = h * glm::dvec3(screen, 1.0);
  return {p.x / p.z, p.y / p.z};
}

Result<HomographyFit> fit_homography(std::span<const Correspondence> points) {
  if (points.size() < 4) {
    return Error{"a homography needs at least 4 correspondences (got " + std::to_string(points.size()) + ")"};
  }
  std::vector<Eigen::Vector2d> screen;
  std::vector<Eigen::Vector2d> pixel;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& c = points[i];
    if (!std::isfinite(c.screen.x) || !std::isfinite(c.screen.y) || !std::isfinite(c.pixel.x) ||
        !std::isfinite(c.pixel.y)) {
      return Error{"points[" + std::to_string(i) + "] has a non-finite coordinate"};
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (points[j].screen == c.screen || points[j].pixel == c.pixel) {
        return Error{"points[" + std::to_string(i) + "] repeats points[" + std::to_string(j) + "]"};
      }
    }
    screen.emplace_back(c.screen.x, c.screen.y);
    pixel.emplace_back(c.pixel.x, c.pixel.y);
  }
  if (collinear(screen)) return Error{"the screen points all lie on one line: they fix no homography"};
  if (collinear(pixel)) return Error{"the pixel points all lie on one line: they fix no homography"};

  const Eigen::Matrix3d ts = normalizing_transform(screen);
  const Eigen::Matrix3d tp = normalizing_transform(pixel);
  const auto n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd a(2 * n, 9);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d s = ts * screen[static_cast<std::size_t>(i)].homogeneous();
    const Eigen::Vector3d p = tp * pixel[static_cast<std::size_t>(i)].homogeneous();
    const double x = p.x() / p.z();
    const double y = p.y() / p.z();
    a.row(2 * i) << 0, 0, 0, -s.x(), -s.y(), -1, y * s.x(), y * s.y(), y;
    a.row(2 * i + 1) << s.x(), s.y(), 1, 0, 0, 0, -x * s.x(), -x * s.y(), -x;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  const Eigen::VectorXd h = svd.matrixV().col(8);
  Eigen::Matrix3d normalized;
  normalized << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d full = tp.inverse() * normalized * ts;
  if (!full.allFinite() || std::abs(full(2, 2)) < 1e-12 * full.norm()) {
    return Error{"the fit is degenerate (h33 ≈ 0: the screen origin maps to infinity)"};
  }
  full /= full(2, 2);

  HomographyFit fit;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) fit.homography[c][r] = full(r, c);
  }
  const auto sv = svd.singularValues();
  fit.condition = sv(7) > 0.0 ? sv(0) / sv(7) : std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (const auto& c : points) {
    const double e = glm::length(apply(fit.homography, c.screen) - c.pixel);
    sum += e * e;
    fit.max_px = std::max(fit.max_px, e);
  }
  fit.rms_px = std::sqrt(sum / static_cast<double>(points.size()));
  if (!std::isfinite(fit.condition) || fit.condition > 1e8) {
    fit.warnings.push_back("the points nearly fix no homography (condition " + std::to_string(fit.condition) +
                           "): spread them over the screen");
  }
  return fit;
}

}  // namespace optique::calib
