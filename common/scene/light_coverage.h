#pragma once
// How much of what a node shows each light reaches: the master's estimate of a
// light's cost to that node, for the automatic light split (docs/design.md, "The
// lighting split"). The node's shader evaluates every light at every pixel but stops early
// where the light does not reach, so a light's cost grows with the share of the
// node's pixels it lights.

#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/definition.h"
#include "scene/state.h"

namespace optique::scene {

// The screen area a node shows, seen from the eye: sample rays from `eye` through
// the centres of an nx × ny grid of cells over the parallelogram
// corner + s·across + t·up, s, t in [0, 1].
struct CoverageGrid {
  glm::dvec3 eye{0.0};
  glm::dvec3 corner{0.0};
  glm::dvec3 across{1.0, 0.0, 0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  int nx = 32;  // > 0
  int ny = 18;  // > 0
  // The least irradiance that counts as a contribution, in the scene's linear
  // units (finite, ≥ 0).
  double threshold = 1e-3;
};

// The point lights a frame has, by index: the scene's own (0 to
// scene.lights.size() - 1), then those applications added (state.point_lights);
// an index between them that holds no light is empty. Switched-off lights are
// here too (lights_off says which).
[[nodiscard]] std::vector<std::optional<PointLight>> frame_lights(const SceneDefinition& scene,
                                                                  const SceneState& state);

// For each light of frame_lights (an empty index: 0), in [0, 1]: the share of the grid's sample rays whose first
// hit (at the state's `now` poses) the light reaches with a noticeable
// contribution: the surface faces it (n·l > 0, n the surface's normal on the
// side the ray sees) and its irradiance intensity·max(colour)·(n·l)/r² is at
// least `threshold`. Rays that meet nothing count for no light. No shadows: the
// renderer draws none, so a light behind an object still costs the pixels it
// would reach.
[[nodiscard]] std::vector<double> light_coverage(const SceneDefinition& scene, const SceneState& state,
                                                 const CoverageGrid& grid);

}  // namespace optique::scene
