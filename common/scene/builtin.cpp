#include "scene/builtin.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace optique::scene {
namespace {

// World frame: metres, y up, the viewer near z = +2 looking down −z; objects sit
// around (0, 1.2, −0.5), behind a front wall at z = 0.
const glm::dvec3 kStage{0.0, 1.2, -0.5};
// Spelled out: a braced {} quaternion is all zeros, not the identity.
const glm::dquat kUpright{1.0, 0.0, 0.0, 0.0};

glm::dquat spin(const glm::dvec3& axis, double radians) { return glm::angleAxis(radians, glm::normalize(axis)); }

SceneScript cubes() {
  // Five cubes on a ring, each turning about its own axis at its own rate.
  SceneScript script{"cubes", {}};
  constexpr int kCount = 5;
  for (int i = 0; i < kCount; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kCount;
    const glm::dvec3 where = kStage + glm::dvec3(0.7 * std::cos(angle), 0.35 * std::sin(angle), 0.0);
    const glm::dvec3 axis(std::cos(angle + 1.0), 1.0, std::sin(angle));
    const double rate = 0.6 + 0.3 * i;  // rad/s
    script.objects.push_back(
        {static_cast<std::uint32_t>(i + 1), "cube-" + std::to_string(i + 1), [where, axis, rate](double t) {
           return Pose{where, spin(axis, rate * t), glm::dvec3(0.25)};
         }});
  }
  return script;
}

SceneScript many_lights() {
  // One slowly turning object; its two dozen lights are static scene content.
  return {"many-lights", {{1, "statue", [](double t) {
                             return Pose{kStage, spin({0, 1, 0}, 0.3 * t), glm::dvec3(0.6)};
                           }}}};
}

SceneScript depth_stack() {
  // Objects at several depths that do not move: after the snapshot, deltas are empty.
  SceneScript script{"depth-stack", {}};
  const std::array<double, 5> depths{0.5, -0.5, -1.5, -3.0, -6.0};
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const glm::dvec3 where(-1.0 + 0.5 * static_cast<double>(i), 1.2, depths[i]);
    script.objects.push_back({static_cast<std::uint32_t>(i + 1), "slab-" + std::to_string(i + 1), [where](double) {
                                return Pose{where, kUpright, glm::dvec3(0.3)};
                              }});
  }
  return script;
}

SceneScript moving_square() {
  // A white square crossing 3 m in 1 s, then jumping back: fast enough that colour
  // fields separate visibly.
  return {"moving-square", {{1, "square", [](double t) {
                               const double phase = t - std::floor(t);
                               return Pose{glm::dvec3(-1.5 + 3.0 * phase, 1.2, -0.2), kUpright, glm::dvec3(0.2)};
                             }}}};
}

struct Entry {
  std::string_view name;
  SceneScript (*make)();
};

constexpr std::array<Entry, 4> kScenes{{
    {"cubes", cubes},
    {"many-lights", many_lights},
    {"depth-stack", depth_stack},
    {"moving-square", moving_square},
}};

constexpr std::array<std::string_view, kScenes.size()> kNames = [] {
  std::array<std::string_view, kScenes.size()> names{};
  for (std::size_t i = 0; i < kScenes.size(); ++i) names[i] = kScenes[i].name;
  return names;
}();

}  // namespace

std::span<const std::string_view> builtin_scene_names() { return kNames; }

bool is_builtin_scene(std::string_view name) { return std::find(kNames.begin(), kNames.end(), name) != kNames.end(); }

Result<SceneScript> builtin_scene(std::string_view name) {
  for (const Entry& e : kScenes) {
    if (e.name == name) return e.make();
  }
  return Error{"unknown built-in scene '" + std::string(name) + "'"};
}

}  // namespace optique::scene
