#include "master/run/light_switches.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "config/light_list.h"

namespace optique::master {
namespace {

constexpr double kSwitchTolerance = 0.5e-6;  // seconds

}  // namespace

std::vector<config::Problem> LightSwitches::check(const config::SceneSource& scene, std::size_t light_count) {
  std::vector<config::Problem> problems;
  for (std::size_t i = 0; i < scene.light_switches.size(); ++i) {
    const config::LightSwitch& entry = scene.light_switches[i];
    const std::string path = "scene.light_switches[" + std::to_string(i) + "]";
    if (auto beyond = config::lights_beyond(entry.off, light_count)) problems.push_back({path + ".off", *beyond});
    if (auto beyond = config::lights_beyond(entry.on, light_count)) problems.push_back({path + ".on", *beyond});
  }
  return problems;
}

LightSwitches LightSwitches::from_config(const config::SceneSource& scene) {
  LightSwitches switches;
  switches.switches_ = scene.light_switches;
  return switches;
}

std::set<std::uint32_t> LightSwitches::off_at(double seconds) const {
  std::set<std::uint32_t> off;
  for (const config::LightSwitch& s : switches_) {
    if (s.time > seconds + kSwitchTolerance) break;
    off.insert(s.off.begin(), s.off.end());
    for (std::uint32_t light : s.on) off.erase(light);
  }
  return off;
}

}  // namespace optique::master
