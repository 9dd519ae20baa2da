#pragma once
// Where a model stands in the room: a glTF file is drawn at its own size in
// metres at the world origin, which for most models is not where the screens
// are (a 6 m truck, a 1.6 m duck on a 1.1 m wall). A placement puts it at a
// position, turned and scaled alike on every axis, or fits it, turned, into a
// box in the room keeping its proportions. The whole scene moves as one:
// every instance, every animated object's pose (so that its velocity, which
// the colour fields and up-conversion use, moves with it) and every light.

#include <optional>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "scene/definition.h"

namespace optique::scene {

// An axis-aligned box, world metres.
struct Box {
  glm::dvec3 low{0.0};
  glm::dvec3 high{0.0};

  [[nodiscard]] glm::dvec3 size() const { return high - low; }
  [[nodiscard]] glm::dvec3 centre() const { return 0.5 * (low + high); }
};

struct Placement {
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // unit, about the model's own origin
  glm::dvec3 position{0.0};                 // where its origin goes, metres
  double scale = 1.0;                       // alike on every axis
  // Instead of position and scale: the model's bounds, turned, scaled to fit
  // inside this box and centred in it.
  struct Fit {
    glm::dvec3 centre{0.0};
    glm::dvec3 size{1.0};  // each > 0
  };
  std::optional<Fit> fit;
};

// The bounds of everything drawn as it stands at t = 0; none when nothing is.
[[nodiscard]] std::optional<Box> world_bounds(const SceneDefinition& scene);

// Places the whole scene; returns the pose it was moved by. A fit is made
// to the model's bounds as turned (not to its bounds' box turned, which would
// leave it smaller than the box allows); a scene with nothing to draw is only
// turned.
Pose place(SceneDefinition& scene, const Placement& placement);

// Moves the whole scene by `pose` (its scale alike on every axis).
void move(SceneDefinition& scene, const Pose& pose);

}  // namespace optique::scene
