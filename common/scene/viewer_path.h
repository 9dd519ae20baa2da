#pragma once

#include <glm/vec3.hpp>

#include "optique/config.pb.h"

namespace optique::scene {

// The eye at simulation time `seconds`: the fixed eye, or the scripted path
// interpolated linearly between its points and looped over its duration.
// `viewer` must be validated (config::validate).
[[nodiscard]] glm::dvec3 eye_at(const config::Viewer& viewer, double seconds);

}  // namespace optique::scene
