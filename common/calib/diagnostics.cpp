#include "calib/diagnostics.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/matrix.hpp>

namespace optique::calib {

Result<Orientation> check_orientation(const glm::dmat3& h, std::span<const geometry::Correspondence> points,
                                      std::span<const std::size_t> used) {
  const double det = glm::determinant(h);
  Orientation o;
  o.jacobian_det_min = std::numeric_limits<double>::infinity();
  o.jacobian_det_max = -std::numeric_limits<double>::infinity();
  std::size_t positive = used.front();
  std::size_t negative = used.front();
  bool any_positive = false;
  bool any_negative = false;
  for (const std::size_t i : used) {
    const double w = geometry::homogeneous_w(h, points[i].screen);
    if (w > 0.0 && !any_positive) positive = i, any_positive = true;
    if (w <= 0.0 && !any_negative) negative = i, any_negative = true;
    const double j = det / (w * w * w);
    o.jacobian_det_min = std::min(o.jacobian_det_min, j);
    o.jacobian_det_max = std::max(o.jacobian_det_max, j);
  }
  if (any_positive && any_negative) {
    const std::size_t first = std::min(positive, negative);
    const std::size_t second = std::max(positive, negative);
    const double w1 = geometry::homogeneous_w(h, points[first].screen);
    const double w2 = geometry::homogeneous_w(h, points[second].screen);
    const double scale = std::max(std::abs(w1), std::abs(w2));
    return Error{fmt::format(
        "the fit flips orientation: points[{}] and points[{}] land on opposite sides of the projector's horizon "
        "(w = {:+.3g} vs {:+.3g}; Jacobian determinant from {:.3g} to {:.3g}), which no projector does: check the "
        "order of the points (a twisted quadrilateral) and that each pixel belongs to its screen point",
        first, second, w1 / scale, w2 / scale, o.jacobian_det_min, o.jacobian_det_max)};
  }
  return o;
}

Result<void> check_horizon_outside_image(const glm::dmat3& h, geometry::ImageSize image, double points_w_sign) {
  const glm::dmat3 inverse = glm::inverse(h);
  const std::array<glm::dvec2, 4> corners{glm::dvec2(0.0, 0.0), glm::dvec2(image.width, 0.0),
                                          glm::dvec2(image.width, image.height), glm::dvec2(0.0, image.height)};
  // The screen point of pixel p is H⁻¹p = s/w: its w has the sign of the w the
  // points have when the pixel is on their side of the horizon.
  for (const auto& corner : corners) {
    const double w = geometry::homogeneous_w(inverse, corner);
    if (!(w * points_w_sign > 0.0)) {
      return Error{fmt::format(
          "the projector's horizon crosses its image: pixel corner ({:g}, {:g}) of the {}×{} image maps beyond "
          "infinity on the screen plane (w = {:+.3g}, the points have {}), but every pixel of a projector facing a "
          "screen lands on it: check the points, or whether they cover enough of the image",
          corner.x, corner.y, image.width, image.height, w, points_w_sign > 0.0 ? "w > 0" : "w < 0")};
    }
  }
  return {};
}

double pixel_coverage(std::span<const geometry::Correspondence> points, std::span<const std::size_t> used,
                      geometry::ImageSize image) {
  glm::dvec2 low = points[used.front()].pixel;
  glm::dvec2 high = low;
  for (const std::size_t i : used) {
    low = glm::min(low, points[i].pixel);
    high = glm::max(high, points[i].pixel);
  }
  // Only the part inside the image counts.
  low = glm::clamp(low, glm::dvec2(0.0), glm::dvec2(image.width, image.height));
  high = glm::clamp(high, glm::dvec2(0.0), glm::dvec2(image.width, image.height));
  return (high.x - low.x) * (high.y - low.y) / (static_cast<double>(image.width) * image.height);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  const double upper = *middle;
  const double lower = *std::max_element(values.begin(), middle);
  return 0.5 * (lower + upper);
}

std::vector<Outlier> gross_outliers(std::span<const double> residuals_px, double floor_px) {
  const double m = median({residuals_px.begin(), residuals_px.end()});
  std::vector<Outlier> outliers;
  for (std::size_t i = 0; i < residuals_px.size(); ++i) {
    const double r = residuals_px[i];
    if (r > kOutlierFactor * m && r > floor_px) outliers.push_back({i, r});
  }
  std::sort(outliers.begin(), outliers.end(),
            [](const Outlier& a, const Outlier& b) { return a.residual_px > b.residual_px; });
  return outliers;
}

}  // namespace optique::calib
