#pragma once
// Scripted paths: points at increasing times, interpolated linearly and looped
// over their duration. The viewer's eye, the focal depth and the gaze point all
// follow such paths.

#include <vector>

#include <glm/vec3.hpp>

#include "optique/config.pb.h"

namespace optique::scene {

// Where `seconds` falls on a looped path with these (increasing) point times:
// between point `from` and point `to`, `fraction` of the way. One point: 0, 0, 0.
struct PathSpot {
  int from = 0;
  int to = 0;
  double fraction = 0.0;
};
[[nodiscard]] PathSpot path_spot(const std::vector<double>& times, double seconds);

// The eye at simulation time `seconds`: the fixed eye, or the scripted path
// interpolated linearly between its points and looped over its duration.
// `viewer` must be validated (config::validate).
[[nodiscard]] glm::dvec3 eye_at(const config::Viewer& viewer, double seconds);

}  // namespace optique::scene
