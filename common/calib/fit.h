#pragma once
// Fitting a projector's homography H (screen metres → projector pixels) from
// measured correspondences: checks on the points, the Hartley-normalized DLT,
// Levenberg–Marquardt refinement of the reprojection error in pixels, an
// optional robust mode (RANSAC), and diagnostics on the result. Fails, saying
// why, on input that fixes no homography or a fit that cannot be a projector;
// warns, with the measured reason, about input that makes the fit fragile.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "calib/diagnostics.h"
#include "calib/robust.h"
#include "geometry/homography.h"
#include "geometry/oblique_depth.h"
#include "util/result.h"

namespace optique::calib {

struct FitOptions {
  bool refine = true;   // false: the DLT alone (for comparisons and benchmarks)
  bool robust = false;  // RANSAC, then the fit on the points that agree
  // The robust threshold; without robust mode, also the least residual that can
  // count as a gross outlier.
  RansacOptions ransac;
  // The projector's image size, when known: enables the checks on coverage, on
  // the horizon crossing the image, and on the oblique depth factor.
  std::optional<geometry::ImageSize> image;
};

// |h33| below this fraction of ‖H‖ (the screen origin on the projector's
// horizon): H is scaled to unit Frobenius norm instead of h33 = 1.
inline constexpr double kTinyH33 = 1e-9;
// A normalized DLT system worse conditioned than this barely fixes H.
inline constexpr double kIllConditioned = 1e8;

struct HomographyFit {
  glm::dmat3 homography{1.0};  // column-major (glm); h33 = 1 unless h33 ≈ 0 (then ‖H‖ = 1, warned)
  double rms_px = 0.0;         // reprojection error over the points used (the inliers in robust mode)
  double max_px = 0.0;
  double condition = 0.0;   // of the normalized DLT system: σ_max / σ_8
  double dlt_rms_px = 0.0;  // the DLT's reprojection error, before refinement
  int refine_iterations = 0;
  std::vector<double> residuals_px;  // every point's, in input order
  std::vector<std::size_t> inliers;  // the points the fit used: all of them unless robust
  // Robust mode: the points left out. Otherwise: points whose residual is far
  // above the median (kept in the fit, and warned about). Worst first.
  std::vector<Outlier> outliers;
  Orientation orientation;
  std::optional<double> coverage;                 // with an image size: pixels' bounding box / image area
  std::optional<geometry::ObliqueDepth> oblique;  // with an image size: A and |a31| + |a32|
  std::vector<std::string> warnings;
};

[[nodiscard]] Result<HomographyFit> fit_homography(std::span<const geometry::Correspondence> points,
                                                   const FitOptions& options = {});

}  // namespace optique::calib
