#include "calib/calibrate_points.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "calib/plane_fit.h"
#include "calib/screen_frame.h"

namespace optique::calib {

Result<Calibration> calibrate_points(const PointsFile& input, FitOptions options) {
  Calibration calibration;
  std::vector<std::string> warnings = input.warnings;
  if (input.kind == PointKind::kScreen) {
    for (std::size_t i = 0; i < input.pixels.size(); ++i) {
      calibration.correspondences.push_back({input.screen[i], input.pixels[i]});
    }
  } else {
    if (input.pixels.size() < 4) {
      return Error{fmt::format("a homography needs at least 4 correspondences (got {})", input.pixels.size())};
    }
    auto plane = fit_plane(input.tracker);
    if (!plane) return Error{"tracker readings: " + plane.error()};
    TrackerSummary tracker;
    tracker.plane_rms_m = plane.value().rms_m;
    tracker.plane_max_m = plane.value().max_m;
    if (input.tracker_to_screen) {
      tracker.tracker_to_screen = *input.tracker_to_screen;
      tracker.frame_given = true;
    } else {
      auto frame = derive_tracker_to_screen(input.tracker, input.pixels, plane.value());
      if (!frame) return Error{"tracker readings: " + frame.error()};
      tracker.tracker_to_screen = frame.value();
    }
    double off_plane = 0.0;
    for (std::size_t i = 0; i < input.pixels.size(); ++i) {
      const glm::dvec3 s = transform_point(tracker.tracker_to_screen, input.tracker[i]);
      off_plane = std::max(off_plane, std::abs(s.z));
      calibration.correspondences.push_back({{s.x, s.y}, input.pixels[i]});
    }
    if (tracker.frame_given && off_plane > std::max(kFrameOffPlaneM, 3.0 * tracker.plane_max_m)) {
      warnings.push_back(fmt::format(
          "the readings lie up to {:.3g} m off the z = 0 plane of the given tracker_to_screen, though they fit their "
          "own plane to {:.3g} m: is that frame from another wall?",
          off_plane, tracker.plane_max_m));
    }
    calibration.tracker = tracker;
  }
  options.image = input.projector;
  auto fit = fit_homography(calibration.correspondences, options);
  if (!fit) return Error{fit.error()};
  calibration.fit = std::move(fit).value();
  calibration.fit.warnings.insert(calibration.fit.warnings.begin(), warnings.begin(), warnings.end());
  return calibration;
}

}  // namespace optique::calib
