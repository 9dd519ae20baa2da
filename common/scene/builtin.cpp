#include "scene/builtin.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "scene/meshes.h"

namespace optique::scene {
namespace {

// World frame: metres, y up, the viewer near z = +2 looking down −z; objects sit
// around (0, 1.2, −0.5), behind a front wall at z = 0.
const glm::dvec3 kStage{0.0, 1.2, -0.5};
// Spelled out: a braced {} quaternion is all zeros, not the identity.
const glm::dquat kUpright{1.0, 0.0, 0.0, 0.0};

glm::dquat spin(const glm::dvec3& axis, double radians) { return glm::angleAxis(radians, glm::normalize(axis)); }

// Adds a mesh and a material and returns their indices.
std::uint32_t add_mesh(SceneDefinition& scene, Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  return static_cast<std::uint32_t>(scene.meshes.size() - 1);
}

std::uint32_t add_material(SceneDefinition& scene, const Material& material) {
  scene.materials.push_back(material);
  return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

// An instance of `mesh` riding on a new animated object.
void add_animated(SceneDefinition& scene, std::uint32_t mesh, std::uint32_t material, std::string name,
                  std::function<Pose(double)> pose_at) {
  const auto id = static_cast<std::uint32_t>(scene.objects.size() + 1);
  scene.objects.push_back({id, std::move(name), std::move(pose_at)});
  scene.instances.push_back({mesh, material, id, glm::dmat4(1.0)});
}

SceneDefinition cubes() {
  // Five unit cubes (scaled to 25 cm) on a ring, each turning about its own axis at
  // its own rate, under three white-ish point lights.
  SceneDefinition scene;
  scene.name = "cubes";
  const auto cube = add_mesh(scene, make_box(glm::vec3(1.0f)));
  constexpr int kCount = 5;
  for (int i = 0; i < kCount; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kCount;
    const glm::dvec3 where = kStage + glm::dvec3(0.7 * std::cos(angle), 0.35 * std::sin(angle), 0.0);
    const glm::dvec3 axis(std::cos(angle + 1.0), 1.0, std::sin(angle));
    const double rate = 0.6 + 0.3 * i;  // rad/s
    const float hue = static_cast<float>(i) / kCount;
    const auto material = add_material(
        scene, {glm::vec3(0.25f + 0.6f * hue, 0.7f - 0.5f * hue, 0.3f + 0.4f * std::abs(0.5f - hue)), 0.0f, 0.4f, {}});
    add_animated(scene, cube, material, "cube-" + std::to_string(i + 1),
                 [where, axis, rate](double t) { return Pose{where, spin(axis, rate * t), glm::dvec3(0.25)}; });
  }
  scene.lights = {{{-1.0, 2.2, 1.0}, {1.0f, 0.95f, 0.9f}, 2.0f},
                  {{1.2, 1.6, 0.8}, {0.9f, 0.95f, 1.0f}, 1.5f},
                  {{0.0, 0.4, 1.2}, {1.0f, 1.0f, 1.0f}, 0.8f}};
  return scene;
}

SceneDefinition many_lights() {
  // One slowly turning object lit by 24 coloured specular lights on a ring.
  SceneDefinition scene;
  scene.name = "many-lights";
  const auto box = add_mesh(scene, make_box(glm::vec3(1.0f)));
  const auto material = add_material(scene, {glm::vec3(0.8f), 0.0f, 0.25f, {}});
  add_animated(scene, box, material, "statue",
               [](double t) { return Pose{kStage, spin({0, 1, 0}, 0.3 * t), glm::dvec3(0.6)}; });
  constexpr int kLights = 24;
  for (int i = 0; i < kLights; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kLights;
    const float h = static_cast<float>(i) / kLights;
    const glm::vec3 colour(0.5f + 0.5f * std::cos(6.2832f * h), 0.5f + 0.5f * std::cos(6.2832f * (h - 0.333f)),
                           0.5f + 0.5f * std::cos(6.2832f * (h - 0.667f)));
    scene.lights.push_back(
        {kStage + glm::dvec3(1.1 * std::cos(angle), 0.5 * std::sin(3.0 * angle), 1.1 * std::sin(angle)), colour, 0.12f});
  }
  return scene;
}

SceneDefinition depth_stack() {
  // Slabs at several depths that do not move: after the snapshot, deltas are empty.
  SceneDefinition scene;
  scene.name = "depth-stack";
  const auto slab = add_mesh(scene, make_box(glm::vec3(1.0f, 1.0f, 0.1f)));
  const std::array<double, 5> depths{0.5, -0.5, -1.5, -3.0, -6.0};
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const glm::dvec3 where(-1.0 + 0.5 * static_cast<double>(i), 1.2, depths[i]);
    const float shade = 0.3f + 0.15f * static_cast<float>(i);
    const auto material = add_material(scene, {glm::vec3(shade, 0.8f - shade * 0.5f, 0.5f), 0.0f, 0.6f, {}});
    add_animated(scene, slab, material, "slab-" + std::to_string(i + 1),
                 [where](double) { return Pose{where, kUpright, glm::dvec3(0.3)}; });
  }
  scene.lights = {{{0.0, 2.5, 2.0}, {1.0f, 1.0f, 1.0f}, 4.0f}};
  scene.ambient = glm::vec3(0.05f);
  return scene;
}

SceneDefinition moving_square() {
  // A white, self-lit square crossing 3 m in 1 s over black, then jumping back:
  // fast enough that colour fields separate visibly.
  SceneDefinition scene;
  scene.name = "moving-square";
  scene.ambient = glm::vec3(0.0f);
  const auto quad = add_mesh(scene, make_quad(1.0f, 1.0f));
  const auto white = add_material(scene, {glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(1.0f)});
  add_animated(scene, quad, white, "square", [](double t) {
    const double phase = t - std::floor(t);
    return Pose{glm::dvec3(-1.5 + 3.0 * phase, 1.2, -0.2), kUpright, glm::dvec3(0.2)};
  });
  return scene;
}

struct Entry {
  std::string_view name;
  SceneDefinition (*make)();
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

Result<SceneDefinition> builtin_scene(std::string_view name) {
  for (const Entry& e : kScenes) {
    if (e.name == name) return e.make();
  }
  return Error{"unknown built-in scene '" + std::string(name) + "'"};
}

}  // namespace optique::scene
