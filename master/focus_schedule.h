#pragma once
// The focal depth of every frame, for a focus/defocus pair: fixed, scripted over
// time, or the depth of what the viewer looks at (a ray from the eye through the
// gaze point on its screen, cast into the scene as it is at that frame). Depths
// are along the screen's normal, as the frustum measures them.

#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "config/installation.h"
#include "protocol/focus.h"
#include "scene/definition.h"
#include "scene/state.h"

namespace optique::master {

class FocusSchedule {
 public:
  // Nothing when the installation has no depth of field. Runs on a validated
  // installation with defaults applied.
  [[nodiscard]] static std::optional<FocusSchedule> make(const config::Installation& installation);

  // The gaze point at simulation time `seconds`, screen metres.
  [[nodiscard]] glm::dvec2 gaze_at(double seconds) const;
  // The frame's focus: its focal depth (clamped to the depth of field's near and
  // far) and gaze point. The scene and state are those of the frame.
  [[nodiscard]] protocol::Focus at(double seconds, const scene::SceneDefinition& scene, const scene::SceneState& state,
                                   const glm::dvec3& eye) const;

 private:
  config::DepthOfField settings_;
  config::Screen screen_;  // the gaze's
};

}  // namespace optique::master
