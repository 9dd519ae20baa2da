#pragma once
// What a fitted H says about the measurement: checks that turn a numerically
// fine fit into an error (it cannot be a projector) or a warning (it probably
// is not what was meant). Each reports the measured quantity behind it.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "geometry/homography.h"
#include "util/result.h"

namespace optique::calib {

struct Orientation {
  // The Jacobian determinant of screen → pixels, over the points used. A front
  // projector maps screen y up to pixel y down: negative. Positive everywhere:
  // the image is mirrored.
  double jacobian_det_min = 0.0;
  double jacobian_det_max = 0.0;
  [[nodiscard]] bool mirrored() const { return jacobian_det_min > 0.0; }
};

// Fails ("the fit flips orientation") when the points in `used` are on both
// sides of the projector's horizon: w = (H·[X Y 1]ᵀ)_z, and with it the sign of
// the Jacobian determinant det(H)/w³, differs among them.
[[nodiscard]] Result<Orientation> check_orientation(const glm::dmat3& h,
                                                    std::span<const geometry::Correspondence> points,
                                                    std::span<const std::size_t> used);

// Fails when the horizon (the pixels whose screen point is at infinity) crosses
// the image: some pixel corner maps to the other side of it than the points do.
[[nodiscard]] Result<void> check_horizon_outside_image(const glm::dmat3& h, geometry::ImageSize image,
                                                       double points_w_sign);

// The bounding box of the used points' pixels as a fraction of the image area.
[[nodiscard]] double pixel_coverage(std::span<const geometry::Correspondence> points, std::span<const std::size_t> used,
                                    geometry::ImageSize image);
// Below this the fit extrapolates over most of the image.
inline constexpr double kLowCoverage = 0.25;

struct Outlier {
  std::size_t index = 0;
  double residual_px = 0.0;
};

// Points whose residual is far above the others': more than kOutlierFactor × the
// median residual and more than `floor_px`. Worst first.
inline constexpr double kOutlierFactor = 6.0;
[[nodiscard]] std::vector<Outlier> gross_outliers(std::span<const double> residuals_px, double floor_px);

[[nodiscard]] double median(std::vector<double> values);

}  // namespace optique::calib
