#pragma once
// Light for a glTF file that brings none: a key, a fill and a rim light placed
// around the scene as the viewer sees it and scaled to its size, and some
// ambient light, so that a model comes out well exposed whatever its size and
// wherever it stands (a photographer's three-point lighting). The lit side of a
// surface facing the viewer shows about its albedo: a texture looks on the
// projector much as it does in an image viewer.

#include <string>

#include <glm/vec3.hpp>

#include "scene/definition.h"

namespace optique::scene {

// Adds the three lights (and raises the ambient term) to `scene`, which has no
// lights, for a viewer at `viewer`; returns what was done, for the log.
[[nodiscard]] std::string add_default_lights(SceneDefinition& scene, const glm::dvec3& viewer);

}  // namespace optique::scene
