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

#include "config/validate.h"
#include "optique/config.pb.h"

namespace optique::master {

class LightSwitches {
 public:
  LightSwitches() = default;  // no switches: every light shines all the time

  // Every problem with the scene's switches, naming the field
  // ("scene.light_switches[2].off"): a time that is not finite, negative, or
  // before the switch above it; a list that does not parse or names a light the
  // scene lacks; a switch that changes nothing (a light switched off while off,
  // or on while on).
  [[nodiscard]] static std::vector<config::Problem> check(const config::Scene& scene, std::size_t light_count);

  // The switches of a scene that `check` accepts (asserted).
  [[nodiscard]] static LightSwitches from_config(const config::Scene& scene, std::size_t light_count);

  // The lights that are off at simulation time `seconds`: a switch at time t
  // applies from t on (to within half a microsecond, so that a switch at 2 s
  // lands on the frame whose nanosecond time rounds to 2 s).
  [[nodiscard]] std::set<std::uint32_t> off_at(double seconds) const;

  [[nodiscard]] bool empty() const { return switches_.empty(); }

 private:
  struct Switch {
    double time = 0.0;
    std::vector<std::uint32_t> off;
    std::vector<std::uint32_t> on;
  };
  std::vector<Switch> switches_;
};

}  // namespace optique::master
