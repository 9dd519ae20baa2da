#include "render/viewpoint.h"

#include <glm/matrix.hpp>

#include "scene/instance_tree.h"

namespace optique::render {

Viewpoint seen_in_world(const scene::SceneState& state, double fraction, const glm::dvec3& eye,
                        const geometry::Frustum& frustum) {
  Viewpoint seen{fraction, eye, frustum};
  const glm::dmat4 to_world = scene::installation_to_world(state, fraction);
  if (to_world == glm::dmat4(1.0)) return seen;  // where the world is: to the bit
  // The frustum's view takes world points back into the installation first;
  // its projection (the screen's, near and far in installation metres) stays.
  seen.eye = glm::dvec3(to_world * glm::dvec4(eye, 1.0));
  seen.frustum.view = frustum.view * glm::inverse(to_world);
  return seen;
}

}  // namespace optique::render
