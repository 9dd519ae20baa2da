#include "scene/instance_tree.h"

#include "scene/definition.h"

namespace optique::scene {

std::optional<glm::dmat4> instance_world(const SceneState& state, const std::string& id, double fraction) {
  glm::dmat4 world(1.0);
  const std::string* at = &id;
  // One more step than the deepest chain a state may hold: a longer one is a cycle.
  for (std::size_t depth = 0; depth <= kMaxInstanceDepth; ++depth) {
    const auto found = state.instances.find(*at);
    if (found == state.instances.end() || !found->second.visible) return std::nullopt;
    world = model_matrix(interpolate(found->second.pose, fraction)) * world;
    if (found->second.parent.empty()) return world;
    at = &found->second.parent;
  }
  return std::nullopt;
}

glm::dmat4 installation_to_world(const SceneState& state, double fraction) {
  const ObjectState& n = state.navigation;
  return model_matrix(n.now == n.next ? n.now : interpolate(n, fraction));
}

}  // namespace optique::scene
