#pragma once
// Where the live scene's instances are (scene/state.h): an instance's pose is
// relative to its parent's, so its place in the world is the chain of poses
// from the world down to it, each at the same moment. An instance is drawn
// only when it and every instance above it are visible: hiding a group hides
// what it holds. The installation itself has a place in the world too: the
// navigation.

#include <optional>
#include <string>

#include <glm/mat4x4.hpp>

#include "scene/state.h"

namespace optique::scene {

// The model matrix of instance `id` `fraction` of a frame after the frame time
// (each pose of the chain interpolated, scene/definition.h), or nullopt when
// it is not in `state`, or it or an instance above it is hidden. A state that
// passed apply_delta has no cycle and no missing parent; a chain that has one
// anyway is not drawn (nullopt), never followed for ever.
[[nodiscard]] std::optional<glm::dmat4> instance_world(const SceneState& state, const std::string& id, double fraction);

// The navigation `fraction` of a frame after the frame time: world ←
// installation. Exactly the same matrix at every fraction when it does not
// change within the frame (a still viewer's fields share one view).
[[nodiscard]] glm::dmat4 installation_to_world(const SceneState& state, double fraction);

}  // namespace optique::scene
