#include "calib/refine.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/LevenbergMarquardt>

#include <cmath>
#include <vector>

#include "calib/eigen_glm.h"

namespace optique::calib {
namespace {

// Residuals (2 per point, normalized pixel units) of Hn with entry `fixed` held
// at 1 and the other 8 entries the parameters.
struct ReprojectionFunctor : Eigen::DenseFunctor<double> {
  ReprojectionFunctor(std::vector<Eigen::Vector3d> screen, std::vector<Eigen::Vector2d> pixel, int fixed)
      : Eigen::DenseFunctor<double>(8, 2 * static_cast<int>(screen.size())),
        screen_(std::move(screen)),
        pixel_(std::move(pixel)),
        fixed_(fixed) {}

  [[nodiscard]] Eigen::Matrix3d matrix(const InputType& x) const {
    Eigen::Matrix3d h;
    int k = 0;
    for (int i = 0; i < 9; ++i) h(i / 3, i % 3) = i == fixed_ ? 1.0 : x(k++);
    return h;
  }

  [[nodiscard]] InputType parameters(const Eigen::Matrix3d& h) const {
    InputType x(8);
    int k = 0;
    for (int i = 0; i < 9; ++i) {
      if (i != fixed_) x(k++) = h(i / 3, i % 3) / h(fixed_ / 3, fixed_ % 3);
    }
    return x;
  }

  int operator()(const InputType& x, ValueType& f) const {
    const Eigen::Matrix3d h = matrix(x);
    for (std::size_t i = 0; i < screen_.size(); ++i) {
      const Eigen::Vector3d v = h * screen_[i];
      const auto r = static_cast<Eigen::Index>(2 * i);
      f(r) = v.x() / v.z() - pixel_[i].x();
      f(r + 1) = v.y() / v.z() - pixel_[i].y();
    }
    return 0;
  }

  int df(const InputType& x, JacobianType& j) const {
    const Eigen::Matrix3d h = matrix(x);
    Eigen::Matrix<double, 2, 9> full;
    for (std::size_t i = 0; i < screen_.size(); ++i) {
      const Eigen::Vector3d& s = screen_[i];
      const Eigen::Vector3d v = h * s;
      const double iw = 1.0 / v.z();
      const double u = v.x() * iw;
      const double w = v.y() * iw;
      full.setZero();
      full.block<1, 3>(0, 0) = s.transpose() * iw;
      full.block<1, 3>(0, 6) = -u * iw * s.transpose();
      full.block<1, 3>(1, 3) = s.transpose() * iw;
      full.block<1, 3>(1, 6) = -w * iw * s.transpose();
      const auto r = static_cast<Eigen::Index>(2 * i);
      int k = 0;
      for (int c = 0; c < 9; ++c) {
        if (c == fixed_) continue;
        j(r, k) = full(0, c);
        j(r + 1, k) = full(1, c);
        ++k;
      }
    }
    return 0;
  }

 private:
  std::vector<Eigen::Vector3d> screen_;
  std::vector<Eigen::Vector2d> pixel_;
  int fixed_;
};

double rms(const Eigen::VectorXd& residuals, double to_pixels) {
  return std::sqrt(residuals.squaredNorm() / (static_cast<double>(residuals.size()) / 2.0)) * to_pixels;
}

}  // namespace

Refinement refine_homography(const glm::dmat3& initial, std::span<const geometry::Correspondence> points) {
  std::vector<glm::dvec2> screen_points;
  std::vector<glm::dvec2> pixel_points;
  for (const auto& c : points) {
    screen_points.push_back(c.screen);
    pixel_points.push_back(c.pixel);
  }
  const Eigen::Matrix3d ts = detail::hartley_transform(screen_points);
  const Eigen::Matrix3d tp = detail::hartley_transform(pixel_points);
  const double to_pixels = 1.0 / tp(0, 0);  // the pixel normalization is a uniform scale
  std::vector<Eigen::Vector3d> screen;
  std::vector<Eigen::Vector2d> pixel;
  for (const auto& c : points) {
    screen.push_back(ts * Eigen::Vector3d(c.screen.x, c.screen.y, 1.0));
    pixel.push_back((tp * Eigen::Vector3d(c.pixel.x, c.pixel.y, 1.0)).head<2>());
  }
  Eigen::Matrix3d hn = tp * detail::to_eigen(initial) * ts.inverse();
  hn /= hn.norm();
  int largest = 0;
  for (int i = 1; i < 9; ++i) {
    if (std::abs(hn(i / 3, i % 3)) > std::abs(hn(largest / 3, largest % 3))) largest = i;
  }

  ReprojectionFunctor functor(std::move(screen), std::move(pixel), largest);
  Eigen::VectorXd x = functor.parameters(hn);
  Eigen::VectorXd start_residuals(functor.values());
  (void)functor(x, start_residuals);

  Eigen::LevenbergMarquardt<ReprojectionFunctor> lm(functor);
  // Stop at relative changes near double precision: exact input must come back exact.
  lm.setXtol(1e-14);
  lm.setFtol(1e-14);
  lm.setGtol(0.0);
  lm.setMaxfev(400);
  Eigen::VectorXd refined = x;
  (void)lm.minimize(refined);
  Eigen::VectorXd refined_residuals(functor.values());
  (void)functor(refined, refined_residuals);

  Refinement result;
  result.iterations = static_cast<int>(lm.iterations());
  result.initial_rms_px = rms(start_residuals, to_pixels);
  const bool better = refined.allFinite() && refined_residuals.allFinite() &&
                      refined_residuals.squaredNorm() <= start_residuals.squaredNorm();
  const Eigen::VectorXd& chosen = better ? refined : x;
  result.rms_px = rms(better ? refined_residuals : start_residuals, to_pixels);
  Eigen::Matrix3d h = tp.inverse() * functor.matrix(chosen) * ts;
  h /= h.norm();
  result.homography = detail::to_glm(h);
  return result;
}

}  // namespace optique::calib
