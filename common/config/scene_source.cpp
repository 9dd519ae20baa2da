// The scene: a built-in one or a glTF file, and when its lights switch.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "config/asset_path.h"
#include "config/light_list.h"
#include "config/sections.h"
#include "scene/builtin.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

// Switch times in order, lists that parse, and no switch that changes nothing (a
// light switched off while off, or on while on). Whether the scene has those
// lights is checked once it is loaded.
std::vector<LightSwitch> light_switches(const schema::Scene& scene, Checker& check) {
  // What each switch changes depends on the ones before it in time: out of
  // order, "light 3 is not off" would blame the wrong switch. Then only the
  // order is reported.
  bool in_order = true;
  for (int i = 1; i < scene.light_switches_size(); ++i) {
    if (scene.light_switches(i).time() < scene.light_switches(i - 1).time()) in_order = false;
  }
  std::vector<LightSwitch> switches;
  std::set<std::uint32_t> off;
  double previous_time = 0.0;
  for (int i = 0; i < scene.light_switches_size(); ++i) {
    const schema::LightSwitch& entry = scene.light_switches(i);
    const std::string path = "scene.light_switches[" + std::to_string(i) + "]";
    if (!std::isfinite(entry.time()) || entry.time() < 0.0) {
      check.fail(path + ".time", "must be a finite number of seconds ≥ 0 (got " + number_text(entry.time()) + ")");
    } else if (entry.time() < previous_time) {
      check.fail(path + ".time", "switches must be in time order: " + number_text(entry.time()) +
                                     " s comes before the switch above it at " + number_text(previous_time) + " s");
    } else {
      previous_time = entry.time();
    }
    if (entry.off().empty() && entry.on().empty()) {
      check.fail(path, "switches nothing: give the lights that go \"off\" or come \"on\"");
    }
    auto going_off = parse_light_list(entry.off());
    if (!going_off) check.fail(path + ".off", going_off.error());
    auto coming_on = parse_light_list(entry.on());
    if (!coming_on) check.fail(path + ".on", coming_on.error());
    if (!going_off || !coming_on) continue;
    switches.push_back({entry.time(), going_off.value(), coming_on.value()});
    if (!in_order) continue;
    std::vector<std::uint32_t> already_off;
    for (std::uint32_t light : going_off.value()) {
      if (!off.insert(light).second) already_off.push_back(light);
    }
    if (!already_off.empty()) {
      check.fail(path + ".off", "light " + format_light_list(already_off) +
                                    " is off already: a switch that changes nothing is probably a typo");
    }
    std::vector<std::uint32_t> not_off;
    for (std::uint32_t light : coming_on.value()) {
      const bool switched_off_here =
          std::find(going_off.value().begin(), going_off.value().end(), light) != going_off.value().end();
      if (switched_off_here || off.erase(light) == 0) not_off.push_back(light);
    }
    if (!not_off.empty()) {
      check.fail(path + ".on", "light " + format_light_list(not_off) +
                                   " is not off: a switch that changes nothing is probably a typo");
    }
  }
  return switches;
}

// How far a placed model may stand from the origin, and how much it may be
// scaled: beyond either, float precision on the nodes is gone.
constexpr double kMaxPlacedAt = 1e6;  // metres
constexpr double kMinPlacedScale = 1e-6;
constexpr double kMaxPlacedScale = 1e6;

// A point within kMaxPlacedAt of the origin.
std::optional<glm::dvec3> placed_point(const std::string& path, const google::protobuf::RepeatedField<double>& v,
                                       Checker& check) {
  const auto point = check.vec3(path, v);
  if (point && glm::length(*point) > kMaxPlacedAt) {
    check.fail(path, "is more than " + number_text(kMaxPlacedAt) + " m from the origin");
    return std::nullopt;
  }
  return point;
}

std::optional<scene::Placement> placement(const schema::Placement& p, Checker& check) {
  const std::string path = "scene.placement";
  scene::Placement placed;
  const std::size_t before = check.count();
  if (!p.rotation().empty()) {
    if (p.rotation_size() != 4) {
      check.fail(path + ".rotation",
                 "must be a quaternion [w, x, y, z] (got " + std::to_string(p.rotation_size()) + " numbers)");
    } else {
      bool finite = true;
      for (int i = 0; i < 4; ++i)
        finite = check.finite(path + ".rotation[" + std::to_string(i) + "]", p.rotation(i)) && finite;
      const glm::dquat q(p.rotation(0), p.rotation(1), p.rotation(2), p.rotation(3));
      const double length = glm::length(q);
      if (finite && length > 1e-9) {
        placed.rotation = q / length;
      } else if (finite) {
        check.fail(path + ".rotation", "has length 0: it is no rotation");
      }
    }
  }
  if (p.has_fit()) {
    if (!p.position().empty() || p.scale() != 0.0) {
      check.fail(path, "give position and scale, or fit, not both: fit sets them");
    }
    const auto centre = placed_point(path + ".fit.centre", p.fit().centre(), check);
    const auto size = check.vec3(path + ".fit.size", p.fit().size());
    if (size) {
      for (int i = 0; i < 3; ++i) {
        if (!((*size)[i] > 0.0 && (*size)[i] <= kMaxPlacedAt)) {
          check.fail(path + ".fit.size[" + std::to_string(i) + "]",
                     "must be in (0, " + number_text(kMaxPlacedAt) + "] metres (got " + number_text((*size)[i]) + ")");
        }
      }
    }
    if (centre && size) placed.fit = scene::Placement::Fit{*centre, *size};
  } else {
    if (!p.position().empty()) {
      if (const auto position = placed_point(path + ".position", p.position(), check)) placed.position = *position;
    }
    if (p.scale() != 0.0) {
      if (!(p.scale() >= kMinPlacedScale && p.scale() <= kMaxPlacedScale)) {
        check.fail(path + ".scale", "must be in [" + number_text(kMinPlacedScale) + ", " +
                                        number_text(kMaxPlacedScale) + "] (got " + number_text(p.scale()) +
                                        "): a model is scaled alike on every axis");
      } else {
        placed.scale = p.scale();
      }
    }
  }
  if (check.count() != before) return std::nullopt;
  return placed;
}

}  // namespace

SceneSource parse_scene(const schema::Scene& s, const std::string& config_dir, Scope scope, Checker& check) {
  SceneSource scene;
  const bool builtin = !s.builtin().empty();
  const bool gltf = !s.gltf().empty();
  if (builtin == gltf) {
    check.fail("scene", builtin ? "give either builtin or gltf, not both" : "name a builtin scene or a gltf file");
    return scene;
  }
  if (builtin && !scene::is_builtin_scene(s.builtin())) {
    check.fail("scene.builtin", "unknown scene '" + s.builtin() +
                                    "' (built-in scenes are: " + util::joined(scene::builtin_scene_names()) + ")");
  }
  scene.builtin = s.builtin();
  scene.light_switches = light_switches(s, check);
  if (s.has_placement()) {
    if (builtin) {
      check.fail("scene.placement", "places a glTF model; a built-in scene stands where it was made for");
    } else {
      scene.placement = placement(s.placement(), check);
    }
  }
  if (gltf) {
    scene.gltf = resolve_asset(s.gltf(), config_dir);
    // A job's scene is the master's, which the node fetches from it.
    if (scope == Scope::installation) {
      const std::filesystem::path file = std::filesystem::path(config_dir) / s.gltf();
      std::error_code ec;
      if (!std::filesystem::is_regular_file(file, ec)) check.fail("scene.gltf", "no such file: " + file.string());
    }
  }
  return scene;
}

}  // namespace optique::config
