#pragma once
// A whole calibration from a points file: tracker readings taken to the screen
// frame (derived from the readings, or the one the file gives), then the
// homography fit with the projector's image size for the diagnostics.

#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>

#include "calib/fit.h"
#include "calib/points_file.h"
#include "util/result.h"

namespace optique::calib {

struct TrackerSummary {
  double plane_rms_m = 0.0;  // readings' distance from their best-fit plane
  double plane_max_m = 0.0;
  glm::dmat4 tracker_to_screen{1.0};  // column-major (glm); rigid
  bool frame_given = false;           // from the file's "tracker_to_screen" rather than derived
};

struct Calibration {
  HomographyFit fit;                                      // its warnings include the file's and the tracker's
  std::vector<geometry::Correspondence> correspondences;  // in the screen frame
  std::optional<TrackerSummary> tracker;                  // tracker input only
};

// A given frame whose z = 0 misses this projector's readings by more than this
// (and more than a few times their own flatness) is probably another wall's.
inline constexpr double kFrameOffPlaneM = 0.005;

// `options.image` is set from the file.
[[nodiscard]] Result<Calibration> calibrate_points(const PointsFile& input, FitOptions options = {});

}  // namespace optique::calib
