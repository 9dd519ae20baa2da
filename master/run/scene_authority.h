#pragma once
// The master owns the scene: frame k happens at simulation time k·T, and every
// dynamic object and the eye are evaluated at that time and at the next frame's,
// and the lights that are switched off at that time.

#include <cstdint>

#include "clock/clock.h"
#include "config/installation.h"
#include "master/run/light_switches.h"
#include "scene/definition.h"
#include "scene/state.h"

namespace optique::master {

class SceneAuthority {
 public:
  // Keeps only what moves (the objects), not the scene's meshes and textures.
  SceneAuthority(std::vector<scene::AnimatedObject> objects, config::Viewer viewer, double frame_rate,
                 LightSwitches switches = {});

  [[nodiscard]] scene::SceneState state_at_frame(std::uint64_t frame) const;
  [[nodiscard]] clock::Nanos simulation_time(std::uint64_t frame) const;
  [[nodiscard]] clock::Nanos frame_period() const { return period_; }

 private:
  std::vector<scene::AnimatedObject> objects_;
  config::Viewer viewer_;
  LightSwitches switches_;
  clock::Nanos period_;
};

}  // namespace optique::master
