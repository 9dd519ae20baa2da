#pragma once
// What every pass of the renderer draws the scene for: a moment and where it is
// seen from, and which light terms it shows. Plain values, no GL.

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "geometry/projection.h"
#include "scene/state.h"

namespace optique::render {

// A moment of the scene and where it is seen from: objects `fraction` of the
// way to their next pose, seen from `eye` through `frustum`.
struct Viewpoint {
  double fraction = 0.0;
  glm::dvec3 eye{0.0};
  geometry::Frustum frustum;

  [[nodiscard]] glm::dmat4 view_projection() const { return frustum.projection * frustum.view; }
  // The same place and frustum (the moment aside): what is drawn from both
  // looks the same where nothing moves.
  [[nodiscard]] bool same_place(const Viewpoint& other) const {
    return eye == other.eye && frustum.view == other.frustum.view && frustum.projection == other.frustum.projection;
  }
};

// What an eye at `eye` sees through `frustum` (both in the installation's
// space) `fraction` of a frame after the frame time, in the world: carried
// there by the state's navigation (scene/instance_tree.h), so that the scene,
// its lights and its instances are drawn as the travelling viewer sees them.
// Every pass's viewpoint is made here.
[[nodiscard]] Viewpoint seen_in_world(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                                      const geometry::Frustum& frustum);

// Which light terms a renderer draws (a node of a stacked group may carry only
// some of them); the point lights are chosen with SceneRenderer::set_lights.
struct LightTerms {
  bool ambient = true;
  bool emissive = true;
};

}  // namespace optique::render
