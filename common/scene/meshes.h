#pragma once
// Procedural meshes for the built-in scenes, centred on the origin, with outward
// normals (flat where the surface has edges, smooth where it is round).

#include "scene/definition.h"

namespace optique::scene {

[[nodiscard]] Mesh make_box(const glm::vec3& size);  // axis-aligned, centred
[[nodiscard]] Mesh make_quad(float width, float height);  // in the xy plane, facing +z

}  // namespace optique::scene
