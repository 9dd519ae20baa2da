// The built-in scenes (common/scene/builtin.h) as a node would draw them: every
// reference resolves, every pose is one a node accepts, the motion is a pure
// function of time, and the up-conversion set moves the way its names say.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <set>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/builtin.h"
#include "util/finite.h"

namespace optique::scene {
namespace {

constexpr double kPi = std::numbers::pi;
const glm::dvec3 kStage{0.0, 1.2, -0.5};
const std::vector<double> kTimes{0.0, 0.37, 5.0};

// The up-conversion set: the test scenes of the frame-rate up-conversion paper.
const std::vector<std::string> kSeedScenes{
    "cube-fast-rotation",    "cube-slow-rotation", "cube-zoom",    "pyramid-fast-rotation",
    "pyramid-slow-rotation", "wheel-rotation",     "wheel-in-out", "falling-ring",
};

std::vector<std::string> all_names() {
  const auto names = builtin_scene_names();
  return {names.begin(), names.end()};
}

SceneDefinition load(const std::string& name) {
  auto scene = builtin_scene(name);
  EXPECT_TRUE(scene.ok()) << scene.error();
  return scene.ok() ? std::move(scene).value() : SceneDefinition{};
}

using util::finite;
bool finite(const Pose& p) { return finite(p.position) && finite(p.scale) && finite(p.rotation); }

// The angle turned from `a` to `b`, whatever the axis.
double angle_between(const glm::dquat& a, const glm::dquat& b) {
  const double w = std::min(1.0, std::abs(glm::dot(a, b)));
  return 2.0 * std::acos(w);
}

const AnimatedObject& only_object(const SceneDefinition& scene) {
  EXPECT_EQ(scene.objects.size(), 1u) << scene.name;
  return scene.objects.front();
}

class EveryBuiltinScene : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryBuiltinScene, BuildsUnderItsName) {
  EXPECT_TRUE(is_builtin_scene(GetParam()));
  const SceneDefinition scene = load(GetParam());
  EXPECT_EQ(scene.name, GetParam());
  EXPECT_FALSE(scene.meshes.empty());
  EXPECT_FALSE(scene.materials.empty());
  EXPECT_FALSE(scene.instances.empty());
  // A scene may be all static (the test probes); otherwise something moves.
  const bool any_animated = std::any_of(scene.instances.begin(), scene.instances.end(),
                                        [](const Instance& i) { return i.object.has_value(); });
  EXPECT_EQ(any_animated, !scene.objects.empty());
}

TEST_P(EveryBuiltinScene, InstancesReferToWhatExists) {
  const SceneDefinition scene = load(GetParam());
  std::set<std::uint32_t> ids;
  for (const AnimatedObject& o : scene.objects) ids.insert(o.id);
  std::set<std::uint32_t> ridden;
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    EXPECT_LT(instance.mesh, scene.meshes.size()) << "instance " << i;
    EXPECT_LT(instance.material, scene.materials.size()) << "instance " << i;
    if (instance.object) {
      EXPECT_TRUE(ids.contains(*instance.object))
          << "instance " << i << " rides on unknown object " << *instance.object;
      ridden.insert(*instance.object);
    }
    for (int c = 0; c < 4; ++c) EXPECT_TRUE(finite(glm::dvec3(instance.transform[c]))) << "instance " << i;
  }
  // No object is animated without being drawn.
  EXPECT_EQ(ridden, ids);
}

TEST_P(EveryBuiltinScene, ObjectIdsAreUniqueAndNamed) {
  const SceneDefinition scene = load(GetParam());
  std::set<std::uint32_t> ids;
  for (const AnimatedObject& o : scene.objects) {
    EXPECT_TRUE(ids.insert(o.id).second) << "duplicate id " << o.id;
    EXPECT_FALSE(o.name.empty()) << o.id;
    EXPECT_TRUE(static_cast<bool>(o.pose_at)) << o.name;
  }
}

TEST_P(EveryBuiltinScene, MeshesAreWellFormed) {
  const SceneDefinition scene = load(GetParam());
  for (const Mesh& mesh : scene.meshes) {
    EXPECT_FALSE(mesh.indices.empty()) << mesh.name;
    EXPECT_EQ(mesh.indices.size() % 3, 0u) << mesh.name;
    for (std::uint32_t i : mesh.indices) ASSERT_LT(i, mesh.vertices.size()) << mesh.name;
  }
}

TEST_P(EveryBuiltinScene, PosesAreFiniteWithUnitRotations) {
  const SceneDefinition scene = load(GetParam());
  for (const AnimatedObject& o : scene.objects) {
    for (double t : kTimes) {
      const Pose p = o.pose_at(t);
      EXPECT_TRUE(finite(p)) << o.name << " t=" << t;
      EXPECT_NEAR(glm::length(p.rotation), 1.0, 1e-9) << o.name << " t=" << t;
      EXPECT_GT(std::min({p.scale.x, p.scale.y, p.scale.z}), 0.0) << o.name << " t=" << t;
    }
  }
}

TEST_P(EveryBuiltinScene, PosesAreAPureFunctionOfTime) {
  const SceneDefinition first = load(GetParam());
  const SceneDefinition second = load(GetParam());
  ASSERT_EQ(first.objects.size(), second.objects.size());
  for (std::size_t i = 0; i < first.objects.size(); ++i) {
    const AnimatedObject& o = first.objects[i];
    EXPECT_EQ(o.id, second.objects[i].id);
    // Out of order, and asked twice: no state carried from one call to the next.
    for (double t : {5.0, 0.0, 0.37, 0.0, 5.0}) {
      const Pose p = o.pose_at(t);
      EXPECT_EQ(p, o.pose_at(t)) << o.name << " t=" << t;
      EXPECT_EQ(p, second.objects[i].pose_at(t)) << o.name << " t=" << t;
    }
  }
}

TEST_P(EveryBuiltinScene, IsLit) {
  const SceneDefinition scene = load(GetParam());
  const bool emissive = std::any_of(scene.materials.begin(), scene.materials.end(), [](const Material& m) {
    return std::max({m.emissive.r, m.emissive.g, m.emissive.b}) > 0.0f;
  });
  const bool ambient = std::max({scene.ambient.r, scene.ambient.g, scene.ambient.b}) > 0.0f;
  EXPECT_TRUE(!scene.lights.empty() || emissive || ambient);
  for (const PointLight& light : scene.lights) {
    EXPECT_TRUE(finite(light.position));
    EXPECT_GT(light.intensity, 0.0f);
    EXPECT_GT(std::max({light.colour.r, light.colour.g, light.colour.b}), 0.0f);
  }
}

// Whatever is drawn reflects or emits something: nothing is invisible black.
TEST_P(EveryBuiltinScene, MaterialsInUseAreNotBlack) {
  const SceneDefinition scene = load(GetParam());
  for (const Instance& instance : scene.instances) {
    ASSERT_LT(instance.material, scene.materials.size());
    const Material& m = scene.materials[instance.material];
    const glm::vec3 visible = m.base_colour + m.emissive;
    EXPECT_GT(std::max({visible.r, visible.g, visible.b}), 0.05f) << "material " << instance.material;
  }
}

INSTANTIATE_TEST_SUITE_P(All, EveryBuiltinScene, ::testing::ValuesIn(all_names()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

TEST(BuiltinScenes, SeedSetAndTheOriginalFourArePresent) {
  const auto names = builtin_scene_names();
  for (const std::string& name : kSeedScenes) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    EXPECT_TRUE(is_builtin_scene(name)) << name;
  }
  for (std::string_view name : {"cubes", "many-lights", "depth-stack", "moving-square"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
  }
  // No name twice.
  EXPECT_EQ(std::set<std::string_view>(names.begin(), names.end()).size(), names.size());
}

TEST(BuiltinScenes, OriginalScenesKeepTheirShape) {
  const SceneDefinition cubes = load("cubes");
  EXPECT_EQ(cubes.objects.size(), 5u);
  EXPECT_EQ(cubes.lights.size(), 3u);
  EXPECT_GE(load("many-lights").lights.size(), 20u);
}

// The colour-field scenes move fast but never jump: a jump would be a velocity
// no eye follows (and the gather would clamp it).
TEST(BuiltinScenes, TheColourFieldScenesMoveWithoutJumps) {
  for (const auto& [name, object, speed] :
       {std::tuple{"scrolling-stripes", "stripes", 1.5}, std::tuple{"pinball", "ball", std::hypot(2.6, 1.9)}}) {
    const SceneDefinition scene = load(name);
    const auto found = std::find_if(scene.objects.begin(), scene.objects.end(),
                                    [wanted = object](const AnimatedObject& o) { return o.name == wanted; });
    ASSERT_NE(found, scene.objects.end()) << name;
    constexpr double kStep = 1.0 / 240.0;
    double fastest = 0.0;
    for (double t = 0.0; t < 6.0; t += kStep) {
      fastest = std::max(fastest, glm::length(found->pose_at(t + kStep).position - found->pose_at(t).position) / kStep);
    }
    EXPECT_LE(fastest, speed * 1.0001) << name;
    EXPECT_GE(fastest, speed * 0.9) << name;
  }
}

class SeedScene : public ::testing::TestWithParam<std::string> {};

TEST_P(SeedScene, OneOrTwoLights) {
  const SceneDefinition scene = load(GetParam());
  EXPECT_GE(scene.lights.size(), 1u);
  EXPECT_LE(scene.lights.size(), 2u);
}

// Visible on a front wall and in a 3 m CAVE: within about 1.2 m of the stage, in
// front of the CAVE's back wall (z = −1.5) and its viewer (z = 0), above its floor.
TEST_P(SeedScene, StaysNearTheStage) {
  const SceneDefinition scene = load(GetParam());
  for (const AnimatedObject& o : scene.objects) {
    for (double t = 0.0; t < 12.0; t += 0.01) {
      const glm::dvec3 p = o.pose_at(t).position;
      EXPECT_LE(glm::length(p - kStage), 1.2) << o.name << " t=" << t;
      EXPECT_GT(p.z, -1.5) << o.name << " t=" << t;
      EXPECT_LT(p.z, 0.0) << o.name << " t=" << t;
      EXPECT_GT(p.y, 0.0) << o.name << " t=" << t;
    }
  }
}

// Continuous motion: no jumps between frames at 120 Hz (the fastest point moves
// well under a metre per frame).
TEST_P(SeedScene, MovesContinuously) {
  const SceneDefinition scene = load(GetParam());
  constexpr double kFrame = 1.0 / 120.0;
  for (const AnimatedObject& o : scene.objects) {
    for (double t = 0.0; t < 8.0; t += kFrame) {
      const Pose a = o.pose_at(t);
      const Pose b = o.pose_at(t + kFrame);
      EXPECT_LT(glm::length(b.position - a.position), 0.1) << o.name << " t=" << t;
      EXPECT_LT(angle_between(a.rotation, b.rotation), 0.2) << o.name << " t=" << t;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(All, SeedScene, ::testing::ValuesIn(kSeedScenes),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

// Turns per second, measured over a short step at several times.
void expect_turn_rate(const std::string& name, double turns_per_second) {
  const SceneDefinition scene = load(name);
  const AnimatedObject& o = only_object(scene);
  constexpr double kStep = 1e-3;
  for (double t : {0.0, 0.37, 5.0}) {
    const double rate = angle_between(o.pose_at(t).rotation, o.pose_at(t + kStep).rotation) / kStep / (2.0 * kPi);
    EXPECT_NEAR(rate, turns_per_second, 0.01 * turns_per_second) << name << " t=" << t;
    // Turning in place.
    EXPECT_EQ(o.pose_at(t).position, o.pose_at(t + kStep).position) << name;
  }
}

TEST(SeedScenes, FastRotationIsTwoTurnsPerSecond) {
  expect_turn_rate("cube-fast-rotation", 2.0);
  expect_turn_rate("pyramid-fast-rotation", 2.0);
}

TEST(SeedScenes, SlowRotationIsAQuarterTurnPerSecond) {
  expect_turn_rate("cube-slow-rotation", 0.25);
  expect_turn_rate("pyramid-slow-rotation", 0.25);
}

TEST(SeedScenes, WheelTurns) {
  const SceneDefinition scene = load("wheel-rotation");
  const AnimatedObject& o = only_object(scene);
  EXPECT_GT(angle_between(o.pose_at(0.0).rotation, o.pose_at(0.1).rotation), 0.1);
  EXPECT_EQ(o.pose_at(0.0).position, o.pose_at(0.1).position);
}

// Moves towards the viewer (+z) and away again along the line of sight, and back
// where it started: its depth range is wide, its x and y fixed.
void expect_zooms(const std::string& name) {
  const SceneDefinition scene = load(name);
  const AnimatedObject& o = only_object(scene);
  double nearest = -1e9, farthest = 1e9;
  bool approached = false, receded = false;
  const glm::dvec3 start = o.pose_at(0.0).position;
  for (double t = 0.0; t < 10.0; t += 0.05) {
    const glm::dvec3 p = o.pose_at(t).position;
    const double dz = o.pose_at(t + 0.05).position.z - p.z;
    approached |= dz > 1e-4;
    receded |= dz < -1e-4;
    nearest = std::max(nearest, p.z);
    farthest = std::min(farthest, p.z);
    EXPECT_DOUBLE_EQ(p.x, start.x) << name << " t=" << t;
    EXPECT_DOUBLE_EQ(p.y, start.y) << name << " t=" << t;
  }
  EXPECT_TRUE(approached) << name;
  EXPECT_TRUE(receded) << name;
  EXPECT_GT(nearest - farthest, 0.5) << name;
}

TEST(SeedScenes, CubeZoomsInAndOut) { expect_zooms("cube-zoom"); }

TEST(SeedScenes, WheelMovesInAndOutWhileTurning) {
  expect_zooms("wheel-in-out");
  const SceneDefinition scene = load("wheel-in-out");
  const AnimatedObject& o = only_object(scene);
  EXPECT_GT(angle_between(o.pose_at(0.0).rotation, o.pose_at(0.1).rotation), 0.1);
}

// The ring falls under gravity from rest, bounces, and comes back up.
TEST(SeedScenes, RingFallsUnderGravityAndBounces) {
  const SceneDefinition scene = load("falling-ring");
  ASSERT_EQ(scene.objects.size(), 1u);
  const AnimatedObject& ring = scene.objects.front();
  const auto y = [&](double t) { return ring.pose_at(t).position.y; };
  // Accelerating downwards at g while falling.
  constexpr double kStep = 0.01;
  for (double t : {0.05, 0.1, 0.2}) {
    const double acceleration = (y(t + kStep) - 2.0 * y(t) + y(t - kStep)) / (kStep * kStep);
    EXPECT_NEAR(acceleration, -9.81, 0.05) << "t=" << t;
  }
  EXPECT_LT(y(0.2), y(0.0));
  // It comes back up to where it started, again and again.
  double lowest = y(0.0);
  bool rose = false;
  for (double t = 0.0; t < 6.0; t += 0.01) {
    lowest = std::min(lowest, y(t));
    rose |= y(t + 0.01) > y(t) + 1e-6;
  }
  EXPECT_TRUE(rose);
  EXPECT_LT(lowest, y(0.0) - 0.5);
  EXPECT_GT(lowest, 0.2);  // on its plinth, not through the floor
  double highest_later = 0.0;
  for (double t = 3.0; t < 6.0; t += 0.001) highest_later = std::max(highest_later, y(t));
  EXPECT_NEAR(highest_later, y(0.0), 1e-3);
}

}  // namespace
}  // namespace optique::scene
