#pragma once
// A show switching its fixtures: the scene's point lights that go dark and come
// on again over simulation time (config Scene.light_switches). The master puts
// the lights that are off into the scene state, so every node draws the same
// lights at the same frame and the automatic split shares out only those that
// shine.

#include <cstddef>
#include <cstdint>
#include <set>
#include <vector>

#include "config/installation.h"
#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::master {

class LightSwitches {
 public:
  LightSwitches() = default;  // no switches: every light shines all the time

  // The lights the scene's switches name that the scene does not have, naming
  // the field ("scene.light_switches[2].off"). (The rest — times in order, lists
  // that parse, no switch that changes nothing — is checked with the config.)
  [[nodiscard]] static std::vector<config::Problem> check(const config::SceneSource& scene, std::size_t light_count);

  // The switches of a scene that `check` accepts.
  [[nodiscard]] static LightSwitches from_config(const config::SceneSource& scene);

  // The lights that are off at simulation time `seconds`: a switch at time t
  // applies from t on (to within half a microsecond, so that a switch at 2 s
  // lands on the frame whose nanosecond time rounds to 2 s).
  [[nodiscard]] std::set<std::uint32_t> off_at(double seconds) const;

  [[nodiscard]] bool empty() const { return switches_.empty(); }

 private:
  std::vector<config::LightSwitch> switches_;
};

}  // namespace optique::master
