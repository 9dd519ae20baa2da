#pragma once
// The input of `optique-master calibrate`: a projector's image size and its
// measured correspondences, each a pixel with either its screen position
// (metres, screen frame) or a 3D tracker reading of where that pixel lands.
//
//   {"projector": {"width": 1920, "height": 1080},
//    "points": [{"pixel": [x, y], "screen": [X, Y]}, ...]}        // or "tracker": [X, Y, Z]
//
// With tracker readings, an optional "tracker_to_screen" (16 numbers, row-major,
// from another projector's calibration) reuses that screen frame instead of
// deriving one, so that all projectors of one wall share it.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "geometry/homography.h"
#include "util/result.h"

namespace optique::calib {

enum class PointKind { kScreen, kTracker };

struct PointsFile {
  geometry::ImageSize projector;
  PointKind kind = PointKind::kScreen;
  std::vector<glm::dvec2> pixels;
  std::vector<glm::dvec2> screen;   // kind == kScreen: one per pixel
  std::vector<glm::dvec3> tracker;  // kind == kTracker: one per pixel
  std::optional<glm::dmat4> tracker_to_screen;
  std::vector<std::string> warnings;  // e.g. a pixel outside the image
};

// Every error names `name` (the file), the point index and the field, e.g.
// "pts.json: points[3].pixel: needs 2 numbers"; syntax errors give line:column.
[[nodiscard]] Result<PointsFile> parse_points_file(std::string_view text, const std::string& name);
[[nodiscard]] Result<PointsFile> read_points_file(const std::string& path);

}  // namespace optique::calib
