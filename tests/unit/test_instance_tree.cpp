// Where a live instance is in the world (common/scene/instance_tree.h) and the
// id the installation's scene goes by (common/scene/asset_id.h).

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "scene/asset_id.h"
#include "scene/instance_tree.h"

namespace optique::scene {
namespace {

InstanceState placed(const std::string& parent, const Pose& now, const Pose& next) {
  InstanceState instance;
  instance.asset = "cubes";
  instance.parent = parent;
  instance.pose = {now, next};
  return instance;
}

Pose at(double x, double y, double z, double turn = 0.0, double scale = 1.0) {
  Pose pose;
  pose.position = {x, y, z};
  pose.rotation = glm::angleAxis(turn, glm::dvec3(0.0, 1.0, 0.0));
  pose.scale = glm::dvec3(scale);
  return pose;
}

glm::dvec3 where(const glm::dmat4& world, const glm::dvec3& point) {
  return glm::dvec3(world * glm::dvec4(point, 1.0));
}

void expect_near(const glm::dvec3& actual, const glm::dvec3& expected) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], 1e-12) << "component " << i;
}

// A child's pose is in its parent's frame: the parent turned a quarter about
// the vertical and scaled by 2 carries the child's offset along with it.
TEST(InstanceWorld, APoseIsInItsParentsFrame) {
  SceneState state;
  const double quarter = std::acos(0.0);
  state.instances["table"] = placed("", at(1.0, 0.0, 0.0, quarter, 2.0), at(1.0, 0.0, 0.0, quarter, 2.0));
  state.instances["cup"] = placed("table", at(0.5, 0.0, 0.0), at(0.5, 0.0, 0.0));
  const auto cup = instance_world(state, "cup", 0.0);
  ASSERT_TRUE(cup.has_value());
  // The cup's origin: 0.5 along the table's x, which the turn sends to −z, doubled.
  expect_near(where(*cup, {0.0, 0.0, 0.0}), {1.0, 0.0, -1.0});
  const auto table = instance_world(state, "table", 0.0);
  ASSERT_TRUE(table.has_value());
  expect_near(where(*table, {0.0, 0.0, 0.0}), {1.0, 0.0, 0.0});
}

// Every pose of the chain is taken at the same moment between now and next.
TEST(InstanceWorld, EachPoseOfTheChainAtTheSameMoment) {
  SceneState state;
  state.instances["cart"] = placed("", at(0.0, 0.0, 0.0), at(2.0, 0.0, 0.0));
  state.instances["box"] = placed("cart", at(0.0, 1.0, 0.0), at(0.0, 3.0, 0.0));
  const auto box = instance_world(state, "box", 0.25);
  ASSERT_TRUE(box.has_value());
  expect_near(where(*box, {0.0, 0.0, 0.0}), {0.5, 1.5, 0.0});
}

// Hiding a group hides what it holds; a missing parent or a cycle (which a
// checked state never has) places nothing rather than looping.
TEST(InstanceWorld, HiddenMissingOrCircularChainsAreNotPlaced) {
  SceneState state;
  state.instances["group"] = placed("", at(0.0, 0.0, 0.0), at(0.0, 0.0, 0.0));
  state.instances["part"] = placed("group", at(1.0, 0.0, 0.0), at(1.0, 0.0, 0.0));
  ASSERT_TRUE(instance_world(state, "part", 0.0).has_value());
  state.instances["group"].visible = false;
  EXPECT_FALSE(instance_world(state, "part", 0.0).has_value());
  EXPECT_FALSE(instance_world(state, "group", 0.0).has_value());
  EXPECT_FALSE(instance_world(state, "nothing", 0.0).has_value());
  state.instances["orphan"] = placed("gone", at(0.0, 0.0, 0.0), at(0.0, 0.0, 0.0));
  EXPECT_FALSE(instance_world(state, "orphan", 0.0).has_value());
  state.instances["a"] = placed("b", at(0.0, 0.0, 0.0), at(0.0, 0.0, 0.0));
  state.instances["b"] = placed("a", at(0.0, 0.0, 0.0), at(0.0, 0.0, 0.0));
  EXPECT_FALSE(instance_world(state, "a", 0.0).has_value());
}

// The deepest chain a state may hold is placed.
TEST(InstanceWorld, TheDeepestAllowedChainIsPlaced) {
  SceneState state;
  std::string parent;
  for (std::size_t i = 0; i < kMaxInstanceDepth; ++i) {
    const std::string id = "i" + std::to_string(i);
    state.instances[id] = placed(parent, at(0.5, 0.0, 0.0), at(0.5, 0.0, 0.0));
    parent = id;
  }
  const auto deepest = instance_world(state, parent, 0.0);
  ASSERT_TRUE(deepest.has_value());
  expect_near(where(*deepest, {0.0, 0.0, 0.0}), {0.5 * kMaxInstanceDepth, 0.0, 0.0});
}

TEST(SceneAssetId, TheBuiltinNameOrTheFilesStem) {
  EXPECT_EQ(scene_asset_id("cubes", ""), "cubes");
  EXPECT_EQ(scene_asset_id("", "/data/models/Torus.gltf"), "Torus");
  EXPECT_EQ(scene_asset_id("", "models/milk truck.glb"), "milk-truck");
  EXPECT_EQ(scene_asset_id("", "models/.hidden"), ".hidden");
  EXPECT_EQ(scene_asset_id("", "dir/"), "scene");
  std::string long_name(100, 'x');
  long_name += ".gltf";
  EXPECT_EQ(scene_asset_id("", long_name), std::string(kMaxInstanceIdLength, 'x'));
  EXPECT_TRUE(is_instance_id(scene_asset_id("", "ünïcode ✓.gltf")));
}

}  // namespace
}  // namespace optique::scene
