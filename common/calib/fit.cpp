#include "calib/fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "calib/dlt.h"
#include "calib/point_checks.h"
#include "calib/refine.h"
#include "util/finite.h"
#include "util/join.h"

namespace optique::calib {
namespace {

// How many points a warning names before it says "and N more".
constexpr std::size_t kNamedOutliers = 8;

std::vector<geometry::Correspondence> select(std::span<const geometry::Correspondence> points,
                                             std::span<const std::size_t> indices) {
  std::vector<geometry::Correspondence> subset;
  subset.reserve(indices.size());
  for (const std::size_t i : indices) subset.push_back(points[i]);
  return subset;
}

double frobenius(const glm::dmat3& h) {
  double sum = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) sum += h[c][r] * h[c][r];
  }
  return std::sqrt(sum);
}

// h33 = 1 when that is a sound scale. When the screen origin is on the
// projector's horizon h33 → 0 and dividing by it would blow the other entries
// up (or divide by zero): then unit norm, with w > 0 at the points.
glm::dmat3 normalize_scale(const glm::dmat3& h, const geometry::Correspondence& reference,
                           std::vector<std::string>& warnings) {
  const double norm = frobenius(h);
  if (std::abs(h[2][2]) >= kTinyH33 * norm) return h / h[2][2];
  const double sign = geometry::homogeneous_w(h, reference.screen) < 0.0 ? -1.0 : 1.0;
  warnings.push_back(fmt::format(
      "h33 ≈ 0 (|h33| = {:.2g} ‖H‖): the screen origin lies on the projector's horizon (a33 → 0), so H is scaled to "
      "unit norm instead of h33 = 1; the fit is sound, but an origin inside the lit area makes a better-scaled file",
      std::abs(h[2][2]) / norm));
  return h * (sign / norm);
}

double rms_over(const glm::dmat3& h, std::span<const geometry::Correspondence> points) {
  double sum = 0.0;
  for (const auto& c : points) {
    const double e = geometry::reprojection_error(h, c);
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(points.size()));
}

std::string outlier_list(std::span<const Outlier> outliers) {
  std::string text = util::joined(outliers.first(std::min(outliers.size(), kNamedOutliers)), [](const Outlier& o) {
    return fmt::format("points[{}] {:.3g} px", o.index, o.residual_px);
  });
  if (outliers.size() > kNamedOutliers) text += fmt::format(" and {} more", outliers.size() - kNamedOutliers);
  return text;
}

void add_image_diagnostics(HomographyFit& fit, std::span<const geometry::Correspondence> points,
                           geometry::ImageSize image) {
  const double coverage = pixel_coverage(points, fit.inliers, image);
  fit.coverage = coverage;
  if (coverage < kLowCoverage) {
    glm::dvec2 low = points[fit.inliers.front()].pixel;
    glm::dvec2 high = low;
    for (const std::size_t i : fit.inliers) {
      low = glm::min(low, points[i].pixel);
      high = glm::max(high, points[i].pixel);
    }
    fit.warnings.push_back(fmt::format(
        "the points cover {:.1f}% of the {}×{} image (their pixels span {:.0f}×{:.0f} px, from ({:.0f}, {:.0f}) to "
        "({:.0f}, {:.0f})): the fit extrapolates over the rest of the image; spread the points over all of it",
        100.0 * coverage, image.width, image.height, high.x - low.x, high.y - low.y, low.x, low.y, high.x, high.y));
  }
  auto oblique = geometry::oblique_depth(fit.homography, image);
  if (!oblique) {
    fit.warnings.push_back("no single-pass oblique projection for this projector: " + oblique.error());
    return;
  }
  const double f = oblique.value().factor;
  fit.oblique = oblique.value();
  const double k = oblique.value().depth_scale;
  if (f >= geometry::kDepthFactorWarning) {
    fit.warnings.push_back(fmt::format(
        "the oblique depth factor |a31| + |a32| is {:.3f} (≥ {}): Raskar's approximated depth (eq. 5) would keep "
        "1 − |a31| − |a32| = {:.3f} of the depth range{}; optique bounds depth over what the projector shows instead, "
        "which keeps {:.3f} of it over the whole image (more over the part on the screen: see check-config){}",
        f, geometry::kDepthFactorWarning, 1.0 - f, f >= 1.0 ? " (nothing: single-pass depth would fail)" : "", k,
        k < 0.1 ? ", so depth precision drops: a less oblique projector helps" : ""));
  }
}

}  // namespace

Result<HomographyFit> fit_homography(std::span<const geometry::Correspondence> points, const FitOptions& options) {
  if (auto checked = check_points(points); !checked) return Error{checked.error()};
  HomographyFit fit;
  fit.warnings = near_line_warnings(points);

  std::vector<std::size_t> used(points.size());
  std::iota(used.begin(), used.end(), std::size_t{0});
  const bool robust = options.robust && points.size() > 4;
  std::optional<DltSolution> dlt_of_used;  // robust mode: the DLT of the current inliers, once known
  if (robust) {
    auto consensus = find_consensus(points, options.ransac);
    if (!consensus) return Error{consensus.error()};
    used = std::move(consensus.value().inliers);
    if (auto checked = check_points(select(points, used)); !checked) {
      return Error{"the points that agree in robust mode fix no homography: " + checked.error()};
    }
    // A 4-point sample's H is rough far from its points: the DLT of all that
    // agree with it finds the rest of the inliers before the (costlier) refinement.
    for (int round = 0; round < 3; ++round) {
      dlt_of_used = solve_dlt(select(points, used));
      if (!dlt_of_used) break;
      auto again = inliers_of(dlt_of_used->homography, points, options.ransac.threshold_px);
      if (again == used || again.size() < 4 || !check_points(select(points, again))) break;
      used = std::move(again);
      dlt_of_used.reset();
    }
  }
  std::vector<geometry::Correspondence> subset = select(points, used);
  const auto dlt = dlt_of_used ? dlt_of_used : solve_dlt(subset);
  if (!dlt || !std::isfinite(dlt->condition)) {
    return Error{"the points fix no homography (the DLT system has a second null vector: condition ∞)"};
  }
  fit.condition = dlt->condition;
  glm::dmat3 h = dlt->homography;
  fit.dlt_rms_px = rms_over(h, subset);

  if (options.refine) {
    // In robust mode the refined H can take in points the DLT left out (or
    // drop some): refit until the set settles.
    for (int round = 0; round < 5; ++round) {
      const Refinement refined = refine_homography(h, subset);
      h = refined.homography;
      fit.refine_iterations += refined.iterations;
      if (!robust) break;
      auto again = inliers_of(h, points, options.ransac.threshold_px);
      if (again == used || again.size() < 4 || !check_points(select(points, again))) break;
      used = std::move(again);
      subset = select(points, used);
    }
  }
  h = normalize_scale(h, subset.front(), fit.warnings);
  if (!util::finite(h)) return Error{"the fit is degenerate: H has non-finite entries"};
  fit.homography = h;
  fit.inliers = used;

  double sum = 0.0;
  fit.residuals_px.reserve(points.size());
  for (const auto& c : points) fit.residuals_px.push_back(geometry::reprojection_error(h, c));
  for (const std::size_t i : used) {
    const double e = fit.residuals_px[i];
    sum += e * e;
    fit.max_px = std::max(fit.max_px, e);
  }
  fit.rms_px = std::sqrt(sum / static_cast<double>(used.size()));

  auto orientation = check_orientation(h, points, used);
  if (!orientation) return Error{orientation.error()};
  fit.orientation = orientation.value();
  if (fit.orientation.mirrored()) {
    fit.warnings.push_back(fmt::format(
        "the image is mirrored (the Jacobian determinant of screen → pixels is positive, {:.3g} to {:.3g}, where a "
        "front projector maps screen y up to pixel y down): expected for rear projection; otherwise check the "
        "screen's y axis",
        fit.orientation.jacobian_det_min, fit.orientation.jacobian_det_max));
  }

  if (robust) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!std::binary_search(used.begin(), used.end(), i)) fit.outliers.push_back({i, fit.residuals_px[i]});
    }
    std::sort(fit.outliers.begin(), fit.outliers.end(),
              [](const Outlier& a, const Outlier& b) { return a.residual_px > b.residual_px; });
    if (!fit.outliers.empty()) {
      fit.warnings.push_back(
          fmt::format("robust mode left out {} of {} points as outliers (over {:.3g} px from the "
                      "fit): {}",
                      fit.outliers.size(), points.size(), options.ransac.threshold_px, outlier_list(fit.outliers)));
    }
  } else {
    fit.outliers = gross_outliers(fit.residuals_px, options.ransac.threshold_px);
    const double m = median(fit.residuals_px);
    if (fit.outliers.size() == 1) {
      fit.warnings.push_back(fmt::format(
          "points[{}] is {:.3g} px from the fit, against a median residual of {:.3g} px: a gross outlier pulls the "
          "whole fit; check that point, or fit in robust mode (--robust), which leaves such points out",
          fit.outliers.front().index, fit.outliers.front().residual_px, m));
    } else if (!fit.outliers.empty()) {
      fit.warnings.push_back(fmt::format(
          "{} points are far from the fit: {} (median residual {:.3g} px): gross outliers pull the whole fit; check "
          "them, or fit in robust mode (--robust), which leaves such points out",
          fit.outliers.size(), outlier_list(fit.outliers), m));
    }
  }

  if (options.image) {
    const double w_sign = geometry::homogeneous_w(h, points[used.front()].screen) > 0.0 ? 1.0 : -1.0;
    if (auto horizon = check_horizon_outside_image(h, *options.image, w_sign); !horizon) {
      return Error{horizon.error()};
    }
    add_image_diagnostics(fit, points, *options.image);
  }
  if (fit.condition > kIllConditioned) {
    fit.warnings.push_back(fmt::format(
        "the points barely fix a homography (condition {:.3g} of the normalized system): spread them over the screen",
        fit.condition));
  }
  return fit;
}

}  // namespace optique::calib
