#include "master/light_switches.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

#include "master/light_share.h"
#include "util/number_text.h"

namespace optique::master {
namespace {

constexpr double kSwitchTolerance = 0.5e-6;  // seconds

}  // namespace

std::vector<config::Problem> LightSwitches::check(const config::Scene& scene, std::size_t light_count) {
  std::vector<config::Problem> problems;
  std::set<std::uint32_t> off;
  double previous_time = 0.0;
  for (int i = 0; i < scene.light_switches_size(); ++i) {
    const config::LightSwitch& entry = scene.light_switches(i);
    const std::string path = "scene.light_switches[" + std::to_string(i) + "]";
    if (!std::isfinite(entry.time()) || entry.time() < 0.0) {
      problems.push_back(
          {path + ".time", "must be a finite number of seconds ≥ 0 (got " + util::number_text(entry.time()) + ")"});
    } else if (entry.time() < previous_time) {
      problems.push_back({path + ".time", "switches must be in time order: " + util::number_text(entry.time()) +
                                              " s comes before the switch above it at " +
                                              util::number_text(previous_time) + " s"});
    } else {
      previous_time = entry.time();
    }
    if (entry.off().empty() && entry.on().empty()) {
      problems.push_back({path, "switches nothing: give the lights that go \"off\" or come \"on\""});
    }
    auto going_off = parse_light_list(entry.off(), light_count);
    if (!going_off) problems.push_back({path + ".off", going_off.error()});
    auto coming_on = parse_light_list(entry.on(), light_count);
    if (!coming_on) problems.push_back({path + ".on", coming_on.error()});
    if (!going_off || !coming_on) continue;
    std::vector<std::uint32_t> already_off;
    for (std::uint32_t light : going_off.value()) {
      if (!off.insert(light).second) already_off.push_back(light);
    }
    if (!already_off.empty()) {
      problems.push_back({path + ".off", "light " + format_light_list(already_off) +
                                             " is off already: a switch that changes nothing is probably a typo"});
    }
    std::vector<std::uint32_t> not_off;
    for (std::uint32_t light : coming_on.value()) {
      const bool switched_off_here =
          std::find(going_off.value().begin(), going_off.value().end(), light) != going_off.value().end();
      if (switched_off_here || off.erase(light) == 0) not_off.push_back(light);
    }
    if (!not_off.empty()) {
      problems.push_back({path + ".on", "light " + format_light_list(not_off) +
                                            " is not off: a switch that changes nothing is probably a typo"});
    }
  }
  return problems;
}

LightSwitches LightSwitches::from_config(const config::Scene& scene, std::size_t light_count) {
  assert(check(scene, light_count).empty());
  LightSwitches switches;
  for (const config::LightSwitch& entry : scene.light_switches()) {
    auto off = parse_light_list(entry.off(), light_count);
    auto on = parse_light_list(entry.on(), light_count);
    if (!off || !on) continue;
    switches.switches_.push_back({entry.time(), std::move(off).value(), std::move(on).value()});
  }
  return switches;
}

std::set<std::uint32_t> LightSwitches::off_at(double seconds) const {
  std::set<std::uint32_t> off;
  for (const Switch& s : switches_) {
    if (s.time > seconds + kSwitchTolerance) break;
    off.insert(s.off.begin(), s.off.end());
    for (std::uint32_t light : s.on) off.erase(light);
  }
  return off;
}

}  // namespace optique::master
