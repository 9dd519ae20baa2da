// Scene state, deltas, snapshots and hashes (common/scene/state.h), and the
// built-in scenes (common/scene/builtin.h).

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/builtin.h"
#include "scene/state.h"

namespace optique::scene {
namespace {

Pose pose(double x, double y, double z, double angle = 0.0, double s = 1.0) {
  Pose p;
  p.position = {x, y, z};
  p.rotation = glm::angleAxis(angle, glm::normalize(glm::dvec3(0.3, 1.0, -0.2)));
  p.scale = {s, s * 0.5, s * 2.0};
  return p;
}

SceneState before_state() {
  SceneState s;
  s.objects[1] = {pose(0.0, 1.0, -0.5, 0.1), pose(0.0, 1.0, -0.5, 0.2)};
  s.objects[2] = {pose(1.0, 1.2, -0.7, 0.0, 0.25), pose(1.0, 1.2, -0.7, 0.0, 0.25)};
  s.objects[5] = {pose(-1.0, 0.3, 0.1), pose(-1.1, 0.3, 0.1)};
  s.objects[9] = {pose(3.0, 3.0, 3.0), pose(3.0, 3.0, 3.0)};
  s.eye_now = {0.0, 1.6, 2.0};
  s.eye_next = {0.0, 1.6, 2.0};
  return s;
}

SceneState after_state() {
  SceneState s = before_state();
  s.objects[1] = {pose(0.0, 1.0, -0.5, 0.2), pose(0.0, 1.0, -0.5, 0.3)};  // moved
  s.objects.erase(5);                                                     // removed
  s.objects[7] = {pose(2.0, 0.0, 0.0), pose(2.0, 0.1, 0.0)};              // added
  s.eye_now = {0.0, 1.6, 2.0};
  s.eye_next = {0.01, 1.6, 2.0};  // the eye moved
  return s;
}

TEST(SceneDelta, ApplyReproducesTargetExactly) {
  const SceneState before = before_state();
  const SceneState after = after_state();
  const wire::StateDelta delta = make_delta(before, after);

  ASSERT_EQ(delta.changed_size(), 2);  // 1 moved, 7 added; 2 and 9 unchanged
  EXPECT_EQ(delta.changed(0).id(), 1u);
  EXPECT_EQ(delta.changed(1).id(), 7u);
  ASSERT_EQ(delta.removed_size(), 1);
  EXPECT_EQ(delta.removed(0), 5u);
  EXPECT_TRUE(delta.has_viewer());

  SceneState state = before;
  auto applied = apply_delta(state, delta);
  ASSERT_TRUE(applied.ok()) << applied.error();
  EXPECT_EQ(state, after);
  EXPECT_EQ(state_hash(state), state_hash(after));
  EXPECT_NE(state_hash(before), state_hash(after));
}

TEST(SceneDelta, SurvivesWireSerialization) {
  const SceneState before = before_state();
  const SceneState after = after_state();
  wire::StateDelta delta;
  ASSERT_TRUE(delta.ParseFromString(make_delta(before, after).SerializeAsString()));
  SceneState state = before;
  ASSERT_TRUE(apply_delta(state, delta).ok());
  EXPECT_EQ(state, after);
  EXPECT_EQ(state_hash(state), state_hash(after));
}

TEST(SceneDelta, IdenticalStatesGiveEmptyDelta) {
  const SceneState s = before_state();
  const wire::StateDelta delta = make_delta(s, s);
  EXPECT_EQ(delta.changed_size(), 0);
  EXPECT_EQ(delta.removed_size(), 0);
  EXPECT_FALSE(delta.has_viewer());

  SceneState copy = s;
  ASSERT_TRUE(apply_delta(copy, delta).ok());
  EXPECT_EQ(copy, s);
}

TEST(SceneDelta, EyeOnlyMoveCarriesViewerOnly) {
  const SceneState before = before_state();
  SceneState after = before;
  after.eye_now.z = 1.9;
  const wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(delta.changed_size(), 0);
  EXPECT_EQ(delta.removed_size(), 0);
  ASSERT_TRUE(delta.has_viewer());
  EXPECT_DOUBLE_EQ(delta.viewer().eye_now().z(), 1.9);
  SceneState state = before;
  ASSERT_TRUE(apply_delta(state, delta).ok());
  EXPECT_EQ(state, after);
}

// A tracked head's turn travels with the eyes: in the delta, the snapshot and
// the hash; an untracked viewer's state is written as before.
TEST(SceneDelta, TheHeadsTurnTravelsWithTheEyes) {
  const SceneState before = before_state();
  SceneState turned = before;
  turned.head_now = glm::angleAxis(0.3, glm::dvec3(0.0, 1.0, 0.0));
  turned.head_next = glm::angleAxis(0.31, glm::dvec3(0.0, 1.0, 0.0));
  EXPECT_NE(state_hash(turned), state_hash(before));
  const wire::StateDelta delta = make_delta(before, turned);
  ASSERT_TRUE(delta.has_viewer());
  EXPECT_TRUE(delta.viewer().has_head_now());
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta));
  EXPECT_EQ(applied, turned);
  auto back = from_snapshot(to_snapshot(turned));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(back.value(), turned);
  EXPECT_FALSE(to_snapshot(before).viewer().has_head_now()) << "untracked: no head written";
  // Half a frame on, halfway through the turn.
  EXPECT_NEAR(glm::angle(head_at(turned, 0.5)), 0.305, 1e-12);
  EXPECT_EQ(eyes_at(before, 0.5), before.eye_now) << "an eye that stays stays to the bit";
}

TEST(ApplyDelta, AHeadTurnThatIsNoRotationIsRefused) {
  SceneState state = before_state();
  const SceneState kept = state;
  wire::StateDelta delta = make_delta(state, state);
  auto& viewer = *delta.mutable_viewer();
  viewer.mutable_eye_now()->set_y(1.6);
  viewer.mutable_eye_next()->set_y(1.6);
  viewer.mutable_head_now()->set_w(2.0);
  viewer.mutable_head_next()->set_w(1.0);
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied);
  EXPECT_NE(applied.error().find("viewer head (now) is not a unit quaternion"), std::string::npos) << applied.error();
  viewer.clear_head_next();
  viewer.mutable_head_now()->set_w(1.0);
  applied = apply_delta(state, delta);
  ASSERT_FALSE(applied);
  EXPECT_NE(applied.error().find("give its turn now and next, or neither"), std::string::npos) << applied.error();
  EXPECT_EQ(state, kept);
}

// The navigation travels as the head does: in the delta, the snapshot and the
// hash; a viewer who does not travel writes none; back to where the world is,
// the delta says so.
TEST(SceneDelta, TheNavigationTravelsWithTheViewer) {
  const SceneState before = before_state();
  SceneState travelled = before;
  Pose there;
  there.position = {100.0, 0.0, -20.0};
  there.rotation = glm::angleAxis(0.5, glm::dvec3(0.0, 1.0, 0.0));
  there.scale = glm::dvec3(3.0);
  Pose further = there;
  further.position.z -= 0.1;
  travelled.navigation = {there, further};
  EXPECT_NE(state_hash(travelled), state_hash(before));
  const wire::StateDelta delta = make_delta(before, travelled);
  ASSERT_TRUE(delta.has_viewer());
  EXPECT_TRUE(delta.viewer().has_navigation_now());
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta));
  EXPECT_EQ(applied, travelled);
  auto back = from_snapshot(to_snapshot(travelled));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(back.value(), travelled);
  EXPECT_FALSE(to_snapshot(before).viewer().has_navigation_now()) << "not travelling: none written";
  const wire::StateDelta home = make_delta(travelled, before);
  ASSERT_TRUE(home.has_viewer());
  ASSERT_TRUE(apply_delta(applied, home));
  EXPECT_EQ(applied, before);
}

TEST(ApplyDelta, ANavigationThatStretchesOrIsHalfGivenIsRefused) {
  SceneState state = before_state();
  const SceneState kept = state;
  SceneState travelled = state;
  travelled.navigation.now.position = {1.0, 0.0, 0.0};
  wire::StateDelta delta = make_delta(state, travelled);
  auto& viewer = *delta.mutable_viewer();
  viewer.mutable_navigation_now()->mutable_scale()->set_x(1.0);
  viewer.mutable_navigation_now()->mutable_scale()->set_y(2.0);
  viewer.mutable_navigation_now()->mutable_scale()->set_z(1.0);
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied);
  EXPECT_NE(applied.error().find("viewer navigation (now) scale must be the same on every axis"), std::string::npos)
      << applied.error();
  for (double s : {0.0, 1e5}) {
    wire::Vec3& scale = *viewer.mutable_navigation_now()->mutable_scale();
    scale.set_x(s);
    scale.set_y(s);
    scale.set_z(s);
    EXPECT_FALSE(apply_delta(state, delta)) << "scale " << s;
  }
  viewer.clear_navigation_next();
  viewer.mutable_navigation_now()->clear_scale();
  applied = apply_delta(state, delta);
  ASSERT_FALSE(applied);
  EXPECT_NE(applied.error().find("viewer navigation: give it now and next, or neither"), std::string::npos)
      << applied.error();
  EXPECT_EQ(state, kept);
}

TEST(SceneDelta, RemovingEveryObject) {
  const SceneState before = before_state();
  SceneState after = before;
  after.objects.clear();
  const wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(delta.changed_size(), 0);
  EXPECT_EQ(delta.removed_size(), 4);
  SceneState state = before;
  ASSERT_TRUE(apply_delta(state, delta).ok());
  EXPECT_TRUE(state.objects.empty());
  EXPECT_EQ(state, after);
  EXPECT_EQ(state_hash(state), state_hash(after));
}

TEST(SceneDelta, LightsSwitchedOffAndOnAgain) {
  SceneState before = before_state();
  before.lights_off = {2, 5};
  SceneState after = before;
  after.lights_off = {0, 5, 19};  // 0 and 19 go dark, 2 shines again
  const wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(std::vector<std::uint32_t>(delta.lights_off().begin(), delta.lights_off().end()),
            (std::vector<std::uint32_t>{0, 19}));
  EXPECT_EQ(std::vector<std::uint32_t>(delta.lights_on().begin(), delta.lights_on().end()),
            std::vector<std::uint32_t>{2});
  EXPECT_EQ(delta.changed_size(), 0);
  EXPECT_NE(state_hash(before), state_hash(after));

  SceneState state = before;
  ASSERT_TRUE(apply_delta(state, delta).ok());
  EXPECT_EQ(state, after);
  EXPECT_EQ(state_hash(state), state_hash(after));
  EXPECT_EQ(make_delta(after, after).lights_off_size() + make_delta(after, after).lights_on_size(), 0);
}

TEST(SceneDelta, LightSwitchesThatChangeNothingAreRefusedWholesale) {
  SceneState base = before_state();
  base.lights_off = {3};
  const auto refused = [&](const wire::StateDelta& delta, std::string_view expected) {
    SceneState state = base;
    auto applied = apply_delta(state, delta);
    ASSERT_FALSE(applied.ok()) << expected;
    EXPECT_NE(applied.error().find(expected), std::string::npos) << applied.error();
    EXPECT_EQ(state, base) << "a refused delta must leave the state as it was";
  };
  wire::StateDelta off_again;
  off_again.add_lights_off(3);
  refused(off_again, "switches off light 3, which is off already");
  wire::StateDelta twice;
  twice.add_lights_off(4);
  twice.add_lights_off(4);
  refused(twice, "switches off light 4, which is off already");
  wire::StateDelta on_while_on;
  on_while_on.add_lights_on(7);
  refused(on_while_on, "switches on light 7, which is not off");
  wire::StateDelta off_and_on;  // one delta cannot do both to one light
  off_and_on.add_lights_off(8);
  off_and_on.add_lights_on(8);
  refused(off_and_on, "switches on light 8, which is not off");
  wire::StateDelta on_twice;
  on_twice.add_lights_on(3);
  on_twice.add_lights_on(3);
  refused(on_twice, "switches on light 3, which is not off");
  // A good change to an object in the same delta is not applied either.
  wire::StateDelta mixed = make_delta(base, after_state());
  mixed.add_lights_on(9);
  refused(mixed, "switches on light 9");
}

TEST(SceneSnapshot, RoundTrip) {
  const SceneState s = after_state();
  wire::Snapshot wire_snapshot;
  ASSERT_TRUE(wire_snapshot.ParseFromString(to_snapshot(s).SerializeAsString()));
  EXPECT_EQ(wire_snapshot.objects_size(), static_cast<int>(s.objects.size()));
  auto back = from_snapshot(wire_snapshot);
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back.value(), s);
  EXPECT_EQ(state_hash(back.value()), state_hash(s));
}

TEST(SceneSnapshot, EmptyStateRoundTrip) {
  const SceneState empty;
  auto back = from_snapshot(to_snapshot(empty));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back.value(), empty);
}

TEST(SceneSnapshot, CarriesTheLightsThatAreOff) {
  SceneState s = after_state();
  s.lights_off = {1, 4, 17};
  auto back = from_snapshot(to_snapshot(s));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back.value(), s);
  EXPECT_EQ(state_hash(back.value()), state_hash(s));

  wire::Snapshot twice = to_snapshot(s);
  twice.add_lights_off(4);
  auto refused = from_snapshot(twice);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("lists light 4 as off twice"), std::string::npos) << refused.error();
}

TEST(SceneSnapshot, DuplicateObjectRejected) {
  wire::Snapshot snapshot = to_snapshot(before_state());
  *snapshot.add_objects() = snapshot.objects(0);
  auto back = from_snapshot(snapshot);
  ASSERT_FALSE(back.ok());
  EXPECT_NE(back.error().find("twice"), std::string::npos) << back.error();
}

TEST(SceneSnapshot, MissingRotationAndScaleMeanIdentity) {
  wire::Snapshot snapshot;
  auto& o = *snapshot.add_objects();
  o.set_id(4);
  o.mutable_now()->mutable_position()->set_x(1.5);
  o.mutable_next()->mutable_position()->set_y(-2.0);
  auto back = from_snapshot(snapshot);
  ASSERT_TRUE(back.ok()) << back.error();
  const ObjectState& state = back.value().objects.at(4);
  EXPECT_EQ(state.now.rotation, glm::dquat(1.0, 0.0, 0.0, 0.0));
  EXPECT_EQ(state.now.scale, glm::dvec3(1.0));
  EXPECT_EQ(state.now.position, glm::dvec3(1.5, 0.0, 0.0));
  EXPECT_EQ(state.next.position, glm::dvec3(0.0, -2.0, 0.0));
}

// Every double of the state feeds the hash: bumping any one by one ulp changes it.
TEST(SceneHash, ChangesWhenAnySingleDoubleChanges) {
  const SceneState base = before_state();
  const std::uint64_t base_hash = state_hash(base);
  auto bump = [](double& v) { v = std::nextafter(v, std::numeric_limits<double>::infinity()); };

  int variants = 0;
  auto check = [&](const char* what, auto&& mutate) {
    SceneState s = base;
    mutate(s);
    ASSERT_NE(s, base) << what;
    EXPECT_NE(state_hash(s), base_hash) << what;
    ++variants;
  };
  check("scale.z", [&](SceneState& s) { bump(s.objects[2].now.scale.z); });
  check("next.scale.z", [&](SceneState& s) { bump(s.objects[9].next.scale.z); });
  check("position.x", [&](SceneState& s) { bump(s.objects[1].now.position.x); });
  check("position.y", [&](SceneState& s) { bump(s.objects[5].next.position.y); });
  check("rotation.w", [&](SceneState& s) { bump(s.objects[1].now.rotation.w); });
  check("rotation.x", [&](SceneState& s) { bump(s.objects[1].next.rotation.x); });
  check("rotation.y", [&](SceneState& s) { bump(s.objects[5].now.rotation.y); });
  check("rotation.z", [&](SceneState& s) { bump(s.objects[9].now.rotation.z); });
  check("eye_now.y", [&](SceneState& s) { bump(s.eye_now.y); });
  check("eye_next.z", [&](SceneState& s) { bump(s.eye_next.z); });
  check("a light off", [&](SceneState& s) { s.lights_off.insert(0); });
  check("navigation.now.position.x", [&](SceneState& s) { bump(s.navigation.now.position.x); });
  check("navigation.next.scale.y", [&](SceneState& s) { bump(s.navigation.next.scale.y); });
  EXPECT_EQ(variants, 13);
}

TEST(SceneHash, DependsOnIdsAndNowNextOrder) {
  const SceneState base = before_state();
  SceneState renumbered = base;
  auto node = renumbered.objects.extract(9);
  node.key() = 10;
  renumbered.objects.insert(std::move(node));
  EXPECT_NE(state_hash(renumbered), state_hash(base));

  SceneState swapped = base;
  std::swap(swapped.objects[1].now, swapped.objects[1].next);
  EXPECT_NE(state_hash(swapped), state_hash(base));

  SceneState eyes = base;
  eyes.eye_now = {1.0, 2.0, 3.0};
  eyes.eye_next = {3.0, 2.0, 1.0};
  SceneState eyes_swapped = eyes;
  std::swap(eyes_swapped.eye_now, eyes_swapped.eye_next);
  EXPECT_NE(state_hash(eyes), state_hash(eyes_swapped));
}

TEST(SceneHash, EqualStatesHashEqually) {
  EXPECT_EQ(state_hash(before_state()), state_hash(before_state()));
  EXPECT_EQ(state_hash(SceneState{}), state_hash(SceneState{}));
}

// 0.0 == -0.0 but their bits (which the hash reads) differ: a sign-of-zero change
// must still reach the node, or its hash drifts from the master's.
TEST(SceneDelta, SignOfZeroChangeKeepsHashesInStep) {
  SceneState before = before_state();
  before.objects[2].now.position.x = 0.0;
  SceneState after = before;
  after.objects[2].now.position.x = -0.0;

  SceneState node = before;
  ASSERT_TRUE(apply_delta(node, make_delta(before, after)).ok());
  EXPECT_EQ(state_hash(node), state_hash(after))
      << "node hash after applying the master's delta differs from the master's hash";
}

TEST(ApplyDelta, NaNPositionFailsAndLeavesStateUnchanged) {
  const SceneState before = before_state();
  // A good change and a removal first, then the bad object: nothing may be applied.
  wire::StateDelta delta = make_delta(before, after_state());
  auto& bad = *delta.add_changed();
  bad.set_id(42);
  bad.mutable_now()->mutable_position()->set_y(std::numeric_limits<double>::quiet_NaN());
  bad.mutable_now()->mutable_rotation()->set_w(1.0);

  SceneState state = before;
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied.ok());
  EXPECT_NE(applied.error().find("object 42"), std::string::npos) << applied.error();
  EXPECT_NE(applied.error().find("non-finite"), std::string::npos) << applied.error();
  EXPECT_EQ(state, before);
  EXPECT_EQ(state_hash(state), state_hash(before));
}

TEST(ApplyDelta, InfiniteViewerFailsAndLeavesStateUnchanged) {
  const SceneState before = before_state();
  wire::StateDelta delta = make_delta(before, after_state());
  delta.mutable_viewer()->mutable_eye_next()->set_x(std::numeric_limits<double>::infinity());
  SceneState state = before;
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied.ok());
  EXPECT_NE(applied.error().find("viewer"), std::string::npos) << applied.error();
  EXPECT_EQ(state, before);
}

TEST(ApplyDelta, RemovingUnknownIdFailsAndLeavesStateUnchanged) {
  const SceneState before = before_state();
  wire::StateDelta delta = make_delta(before, after_state());
  delta.add_removed(1234);
  SceneState state = before;
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied.ok());
  EXPECT_NE(applied.error().find("1234"), std::string::npos) << applied.error();
  EXPECT_EQ(state, before);
}

TEST(ApplyDelta, NonUnitQuaternionRejected) {
  const SceneState before = before_state();
  wire::StateDelta delta;
  auto& o = *delta.add_changed();
  o.set_id(1);
  auto& q = *o.mutable_next()->mutable_rotation();
  q.set_w(1.0);
  q.set_x(0.01);  // norm 1.00005: off by more than 1e-6
  SceneState state = before;
  auto applied = apply_delta(state, delta);
  ASSERT_FALSE(applied.ok());
  EXPECT_NE(applied.error().find("unit quaternion"), std::string::npos) << applied.error();
  EXPECT_EQ(state, before);

  // A zero quaternion (all fields left at 0 but present) is no rotation either.
  wire::StateDelta zero;
  auto& z = *zero.add_changed();
  z.set_id(1);
  z.mutable_now()->mutable_rotation();
  EXPECT_FALSE(apply_delta(state, zero).ok());
  EXPECT_EQ(state, before);
}

TEST(ApplyDelta, NearlyUnitQuaternionAccepted) {
  SceneState state = before_state();
  wire::StateDelta delta;
  auto& o = *delta.add_changed();
  o.set_id(1);
  auto& q = *o.mutable_now()->mutable_rotation();
  q.set_w(1.0 + 1e-9);
  auto applied = apply_delta(state, delta);
  ASSERT_TRUE(applied.ok()) << applied.error();
  EXPECT_DOUBLE_EQ(state.objects.at(1).now.rotation.w, 1.0 + 1e-9);
}

// --- built-in scenes ---------------------------------------------------------------

bool finite(const Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(p.rotation.w) && std::isfinite(p.rotation.x) && std::isfinite(p.rotation.y) &&
         std::isfinite(p.rotation.z) && std::isfinite(p.scale.x) && std::isfinite(p.scale.y) &&
         std::isfinite(p.scale.z);
}

InstanceState instance(const std::string& asset, const std::string& parent, double x) {
  InstanceState i;
  i.asset = asset;
  i.parent = parent;
  i.pose = {pose(x, 1.0, 0.0, 0.1), pose(x + 0.1, 1.0, 0.0, 0.2)};
  return i;
}

SceneState with_instances() {
  SceneState s = before_state();
  s.instances["table"] = instance("table", "", 0.0);
  s.instances["cup"] = instance("cup", "table", 0.5);
  s.instances["lamp"] = instance("lamp", "", 2.0);
  s.instances["lamp"].visible = false;
  s.instances["lamp"].emissive = {4.0, 3.0, 2.0};
  s.instances["lamp"].animation = AnimationTimes{3.0, 3.0};  // paused at 3 s
  return s;
}

// The instances an application placed travel as the objects do: in the
// snapshot, in the delta only what changed, and in the hash.
TEST(SceneInstances, TravelInSnapshotsDeltasAndTheHash) {
  const SceneState before = with_instances();
  auto snapshot = from_snapshot(to_snapshot(before));
  ASSERT_TRUE(snapshot) << snapshot.error();
  EXPECT_EQ(snapshot.value(), before);
  EXPECT_EQ(state_hash(snapshot.value()), state_hash(before));

  SceneState after = before;
  after.instances["cup"].base_color = {1.0, 0.0, 0.0, 0.5};
  after.instances["cup"].parent = "lamp";
  after.instances.erase("table");
  after.instances["chair"] = instance("chair", "", -1.0);
  EXPECT_NE(state_hash(after), state_hash(before));
  const wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(delta.instances_changed_size(), 2);  // the cup and the chair; not the lamp
  ASSERT_EQ(delta.instances_removed_size(), 1);
  EXPECT_EQ(delta.instances_removed(0), "table");
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta)) << apply_delta(applied, delta).error();
  EXPECT_EQ(applied, after);
  EXPECT_EQ(state_hash(applied), state_hash(after));
  EXPECT_EQ(make_delta(after, after).instances_changed_size(), 0);
  // The pose packed: once for an instance that stands still over the frame,
  // twice for one that moves; an instance that only moved travels as a move.
  SceneState still = after;
  still.instances["cup"].pose.next = still.instances["cup"].pose.now;
  SceneState moving = still;
  moving.instances["cup"].pose.next.position.x += 0.25;
  for (const auto& [from, to, numbers] : {std::tuple{&after, &still, 10}, std::tuple{&still, &moving, 20}}) {
    const wire::StateDelta packed = make_delta(*from, *to);
    EXPECT_EQ(packed.instances_changed_size(), 0);
    ASSERT_EQ(packed.instances_moved_size(), 1);
    EXPECT_EQ(packed.instances_moved(0).id(), "cup");
    EXPECT_EQ(packed.instances_moved(0).pose_size(), numbers);
    SceneState applied_packed = *from;
    ASSERT_TRUE(apply_delta(applied_packed, packed));
    EXPECT_EQ(applied_packed, *to);
  }
  // From a peer that lists them out of order: the same state.
  wire::StateDelta reversed = delta;
  std::reverse(reversed.mutable_instances_changed()->begin(), reversed.mutable_instances_changed()->end());
  ASSERT_NE(reversed.instances_changed(0).id(), delta.instances_changed(0).id());
  SceneState applied_reversed = before;
  ASSERT_TRUE(apply_delta(applied_reversed, reversed));
  EXPECT_EQ(applied_reversed, after);
}

// A node keeps the instances' part of the hash as deltas change them
// (apply_delta with InstancesHash): after each delta it is what hashing every
// instance again gives, and a refused delta leaves it as it was.
TEST(SceneHash, TheInstancesKeptThroughDeltasHashAsTheWholeState) {
  SceneState state = with_instances();
  InstancesHash kept = instances_hash(state);
  std::vector<SceneState> targets;
  SceneState next = state;
  next.instances["cup"].pose.now.position.x += 0.25;  // a move
  targets.push_back(next);
  next.instances["cup"].parent = "lamp";                 // a change
  next.instances["stool"] = instance("stool", "", 3.0);  // a new one
  targets.push_back(next);
  next.instances.erase("table");  // a removal
  next.instances["lamp"].pose.next.position.y += 1.0;
  targets.push_back(next);
  next.instances.clear();
  targets.push_back(next);
  for (const SceneState& target : targets) {
    ASSERT_TRUE(apply_delta(state, make_delta(state, target), kept));
    EXPECT_EQ(state, target);
    EXPECT_EQ(kept, instances_hash(state));
    EXPECT_EQ(state_hash(state, kept), state_hash(state));
  }
  wire::StateDelta refused;
  refused.add_instances_removed("ghost");
  const InstancesHash before = kept;
  EXPECT_FALSE(apply_delta(state, refused, kept));
  EXPECT_EQ(kept, before);
}

// The master's staged edits: the instances named, each as it is then, or
// removed; nothing else of the state, and nothing for one that did not change.
TEST(SceneInstances, AnInstanceDeltaCarriesTheNamedInstancesOnly) {
  const SceneState before = with_instances();
  std::map<std::string, std::optional<InstanceState>> after;
  after["cup"] = before.instances.at("cup");
  after["cup"]->pose.now.position.z -= 1.0;        // moved
  after["lamp"] = before.instances.at("lamp");     // the same
  after["stool"] = instance("stool", "cup", 1.0);  // new, on the moved cup
  after["ghost"] = std::nullopt;                   // neither there nor here
  const wire::StateDelta delta = make_instance_delta(before, after);
  EXPECT_EQ(delta.instances_moved_size(), 1);
  EXPECT_EQ(delta.instances_changed_size(), 1);
  EXPECT_EQ(delta.instances_removed_size(), 0);
  EXPECT_FALSE(delta.has_viewer());
  EXPECT_EQ(delta.changed_size(), 0);
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta));
  SceneState expected = before;
  expected.instances["cup"] = *after["cup"];
  expected.instances["stool"] = *after["stool"];
  EXPECT_EQ(applied, expected);

  const wire::StateDelta removal = make_instance_delta(expected, {{"stool", std::nullopt}});
  ASSERT_EQ(removal.instances_removed_size(), 1);
  EXPECT_EQ(removal.instances_removed(0), "stool");
}

// The point lights applications add: in snapshots and deltas, each field in
// the hash, and a state without any hashing as it did before there were any
// (the pinned values of SceneHash.HasTheseValues).
TEST(ScenePointLights, TravelInSnapshotsDeltasAndTheHash) {
  const SceneState before = with_instances();
  SceneState after = before;
  after.point_lights[3] = {{0.0, 2.0, -1.0}, {1.0, 0.5, 0.25}, 4.0};
  after.point_lights[9] = {{1.0, 2.0, -1.0}, {1.0, 1.0, 1.0}, 1.0};
  EXPECT_NE(state_hash(after), state_hash(before));
  auto snapshot = from_snapshot(to_snapshot(after));
  ASSERT_TRUE(snapshot) << snapshot.error();
  EXPECT_EQ(snapshot.value(), after);

  wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(delta.point_lights_set_size(), 2);
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta));
  EXPECT_EQ(applied, after);
  EXPECT_EQ(state_hash(applied), state_hash(after));

  // One moved, one removed: only they travel.
  SceneState later = after;
  later.point_lights[3].position.y = 2.5;
  later.point_lights.erase(9);
  delta = make_delta(after, later);
  ASSERT_EQ(delta.point_lights_set_size(), 1);
  EXPECT_EQ(delta.point_lights_set(0).light(), 3u);
  ASSERT_EQ(delta.point_lights_removed_size(), 1);
  EXPECT_EQ(delta.point_lights_removed(0), 9u);
  ASSERT_TRUE(apply_delta(applied, delta));
  EXPECT_EQ(applied, later);
  EXPECT_EQ(make_delta(later, later).point_lights_set_size(), 0);

  const std::vector<void (*)(PointLightState&)> changes{[](PointLightState& l) { l.position.z += 1e-9; },
                                                        [](PointLightState& l) { l.colour.g = 0.0; },
                                                        [](PointLightState& l) { l.intensity = 2.0; }};
  for (const auto& change : changes) {
    SceneState changed = later;
    change(changed.point_lights[3]);
    EXPECT_NE(state_hash(changed), state_hash(later));
    const wire::StateDelta one = make_delta(later, changed);
    EXPECT_EQ(one.point_lights_set_size(), 1);
  }
  SceneState moved_index = later;
  moved_index.point_lights[4] = moved_index.point_lights[3];
  moved_index.point_lights.erase(3);
  EXPECT_NE(state_hash(moved_index), state_hash(later));
}

TEST(ScenePointLights, WhatAPeerMayNotSendIsRefusedAndTheStateKept) {
  SceneState state = with_instances();
  state.point_lights[2] = {{0.0, 1.0, 0.0}, {1.0, 1.0, 1.0}, 1.0};
  const SceneState kept = state;
  const auto light = [](std::uint32_t index, std::vector<double> position, std::vector<double> colour,
                        double intensity) {
    wire::StateDelta d;
    auto& l = *d.add_point_lights_set();
    l.set_light(index);
    l.mutable_position()->Add(position.begin(), position.end());
    l.mutable_colour()->Add(colour.begin(), colour.end());
    l.set_intensity(intensity);
    return d;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<std::string, wire::StateDelta>> bad{
      {"a NaN position", light(5, {nan, 0, 0}, {1, 1, 1}, 1)},
      {"a position too far", light(5, {2e6, 0, 0}, {1, 1, 1}, 1)},
      {"two numbers for a position", light(5, {0, 0}, {1, 1, 1}, 1)},
      {"a negative colour", light(5, {0, 0, 0}, {-1, 1, 1}, 1)},
      {"an infinite intensity", light(5, {0, 0, 0}, {1, 1, 1}, std::numeric_limits<double>::infinity())},
      {"an intensity too large", light(5, {0, 0, 0}, {1, 1, 1}, 2e6)},
      {"an index too large", light(kMaxLightIndex, {0, 0, 0}, {1, 1, 1}, 1)},
  };
  wire::StateDelta twice = light(5, {0, 0, 0}, {1, 1, 1}, 1);
  *twice.add_point_lights_set() = twice.point_lights_set(0);
  bad.emplace_back("one light set twice", twice);
  wire::StateDelta missing;
  missing.add_point_lights_removed(7);
  bad.emplace_back("a light removed that is not there", missing);
  wire::StateDelta set_and_removed = light(2, {0, 0, 0}, {1, 1, 1}, 1);
  set_and_removed.add_point_lights_removed(2);
  bad.emplace_back("a light set and removed", set_and_removed);
  wire::StateDelta too_many;
  for (std::uint32_t i = 0; i < kMaxAddedLights; ++i)
    *too_many.add_point_lights_set() = light(10 + i, {0, 0, 0}, {1, 1, 1}, 1).point_lights_set(0);
  bad.emplace_back("more lights than a node takes", too_many);
  for (const auto& [what, delta] : bad) {
    const auto applied = apply_delta(state, delta);
    EXPECT_FALSE(applied) << what;
    if (!applied) {
      EXPECT_NE(applied.error().find("point light"), std::string::npos) << what << ": " << applied.error();
    }
    EXPECT_EQ(state, kept) << what;
    wire::Snapshot snapshot = to_snapshot(kept);
    snapshot.mutable_point_lights()->MergeFrom(delta.point_lights_set());
    // In a snapshot, each of them is refused too (a light set twice: there twice).
    if (!delta.point_lights_set().empty()) {
      EXPECT_FALSE(from_snapshot(snapshot)) << what;
    }
  }
  // Just within: 64 lights, the largest index, the bounds themselves.
  wire::StateDelta most;
  for (std::uint32_t i = 0; i + 1 < kMaxAddedLights; ++i)
    *most.add_point_lights_set() = light(10 + i, {1e6, 0, -1e6}, {0, 1e3, 0}, 1e6).point_lights_set(0);
  EXPECT_TRUE(apply_delta(state, most));
  EXPECT_EQ(state.point_lights.size(), kMaxAddedLights);
}

TEST(SceneInstances, EachFieldChangesTheHash) {
  const SceneState base = with_instances();
  const std::vector<void (*)(InstanceState&)> changes{[](InstanceState& i) { i.asset = "teapot"; },
                                                      [](InstanceState& i) { i.parent = "lamp"; },
                                                      [](InstanceState& i) { i.pose.next.scale.y *= 2; },
                                                      [](InstanceState& i) { i.visible = false; },
                                                      [](InstanceState& i) { i.base_color.a = 0.5; },
                                                      [](InstanceState& i) { i.emissive.b = 0.0; },
                                                      [](InstanceState& i) {
                                                        i.animation = AnimationTimes{0.0, 0.0};
                                                      },
                                                      [](InstanceState& i) {
                                                        i.animation = AnimationTimes{0.0, 1.0 / 60.0};
                                                      }};
  for (std::size_t k = 0; k < changes.size(); ++k) {
    SceneState changed = base;
    changes[k](changed.instances["cup"]);
    EXPECT_NE(state_hash(changed), state_hash(base)) << "change " << k;
    const wire::StateDelta delta = make_delta(base, changed);
    EXPECT_EQ(delta.instances_changed_size() + delta.instances_moved_size(), 1) << "change " << k;
    EXPECT_EQ(delta.instances_moved_size(), k == 2 ? 1 : 0) << "change " << k << ": only the pose is a move";
    SceneState applied = base;
    ASSERT_TRUE(apply_delta(applied, delta)) << "change " << k;
    EXPECT_EQ(applied, changed) << "change " << k;
  }
}

// Instances that only moved travel as moves (id and pose): applied in place,
// in the master's order or a peer's; what a peer may not send is refused and
// leaves the state as it was.
TEST(SceneInstances, MovesAreAppliedInPlaceAndWhatCannotBeMovedIsRefused) {
  SceneState before = with_instances();
  for (int i = 0; i < 50; ++i) before.instances["m" + std::to_string(100 + i)] = instance("torus", "", i * 0.1);
  SceneState after = before;
  for (auto& [id, instance] : after.instances) {
    if (id[0] == 'm' && (id.back() - '0') % 3 != 0) instance.pose.now.position.y += 1.0;  // every third stays
  }
  after.instances["m149"].pose.next.position.z = 2.0;
  const wire::StateDelta delta = make_delta(before, after);
  EXPECT_EQ(delta.instances_changed_size(), 0);
  EXPECT_GT(delta.instances_moved_size(), 30);
  SceneState applied = before;
  ASSERT_TRUE(apply_delta(applied, delta));
  EXPECT_EQ(applied, after);
  EXPECT_EQ(state_hash(applied), state_hash(after));
  wire::StateDelta reversed = delta;
  std::reverse(reversed.mutable_instances_moved()->begin(), reversed.mutable_instances_moved()->end());
  SceneState applied_reversed = before;
  ASSERT_TRUE(apply_delta(applied_reversed, reversed));
  EXPECT_EQ(applied_reversed, after);

  const auto move = [&](const std::string& id) {
    wire::StateDelta d;
    auto& m = *d.add_instances_moved();
    m.set_id(id);
    *m.mutable_pose() = delta.instances_moved(0).pose();
    return d;
  };
  std::vector<std::pair<std::string, wire::StateDelta>> bad{{"not there", move("ghost")}, {"not an id", move("a b")}};
  wire::StateDelta twice = move("m101");
  *twice.add_instances_moved() = twice.instances_moved(0);
  bad.emplace_back("moved twice", twice);
  wire::StateDelta twice_apart = move("m101");
  *twice_apart.add_instances_moved() = move("m102").instances_moved(0);
  *twice_apart.add_instances_moved() = twice_apart.instances_moved(0);
  bad.emplace_back("moved twice, not next to each other", twice_apart);
  wire::StateDelta removed = move("m101");
  removed.add_instances_removed("m101");
  bad.emplace_back("moved and removed", removed);
  SceneState hidden = before;
  hidden.instances["cup"].visible = false;
  wire::StateDelta changed = make_delta(before, hidden);
  ASSERT_EQ(changed.instances_changed_size(), 1);
  *changed.add_instances_moved() = move("cup").instances_moved(0);
  bad.emplace_back("moved and changed", changed);
  wire::StateDelta short_pose = move("m101");
  short_pose.mutable_instances_moved(0)->mutable_pose()->RemoveLast();
  bad.emplace_back("a pose of 9 numbers", short_pose);
  wire::StateDelta nan_pose = move("m101");
  nan_pose.mutable_instances_moved(0)->set_pose(0, std::numeric_limits<double>::quiet_NaN());
  bad.emplace_back("a NaN position", nan_pose);
  wire::StateDelta unit = move("m101");
  unit.mutable_instances_moved(0)->set_pose(3, 2.0);
  bad.emplace_back("a rotation of length 2", unit);
  for (const auto& [what, d] : bad) {
    SceneState state = before;
    const auto outcome = apply_delta(state, d);
    EXPECT_FALSE(outcome) << what;
    EXPECT_EQ(state, before) << what;
  }
}

// Ids and assets are hashed eight bytes a word: one byte changed anywhere in a
// name (first word, past it, the last of 64), or the same letters split
// otherwise between two names, changes the hash.
TEST(SceneInstances, EveryByteOfANameChangesTheHash) {
  const SceneState base = with_instances();
  const std::string long_asset(kMaxInstanceIdLength, 'a');
  SceneState long_named = base;
  long_named.instances["cup"].asset = long_asset;
  const std::uint64_t long_hash = state_hash(long_named);
  for (const std::size_t at :
       {std::size_t{0}, std::size_t{7}, std::size_t{8}, std::size_t{9}, kMaxInstanceIdLength - 1}) {
    SceneState changed = long_named;
    changed.instances["cup"].asset[at] = 'b';
    EXPECT_NE(state_hash(changed), long_hash) << "byte " << at;
  }
  SceneState one = base;
  one.instances["cup"].asset = "tablecl";
  one.instances["cup"].parent = "oth";
  SceneState other = base;
  other.instances["cup"].asset = "tablec";
  other.instances["cup"].parent = "loth";
  EXPECT_NE(state_hash(one), state_hash(other));
}

// The hash is a function of the state alone, the same on every machine and in
// every build: these are its values for two states (change them only with the
// function, in a commit that says so; masters and nodes of one release agree).
// (Built of exact numbers, nothing a maths library computes.)
TEST(SceneHash, HasTheseValues) {
  SceneState state;
  state.objects[3].now.position = {0.5, 1.25, -2.0};
  state.objects[3].next.position = {0.75, 1.25, -2.0};
  state.eye_now = {0.0, 1.5, 2.0};
  state.eye_next = {0.0, 1.5, 2.25};
  state.lights_off = {1};
  state.instances["cup"].asset = "a-teacup-of-the-long-name";
  state.instances["cup"].pose.now.scale = {0.5, 0.5, 0.5};
  state.instances["cup"].emissive = {2.0, 0.0, 0.0};
  state.instances["saucer"].asset = "a";
  state.instances["saucer"].animation = AnimationTimes{2.0, 2.25};
  EXPECT_EQ(state_hash(SceneState{}), 0x9e4df0ed2b31c960u);
  // The instances as the sum of each one's hash (so that a node follows a few
  // moved of thousands without hashing them all again): from 0xc9b5facc0a617813.
  EXPECT_EQ(state_hash(state), 0x977e1e590798ca65u);
}

// What the parents make of the instances is checked as the delta would leave
// them, and a refused delta leaves the state as it was.
TEST(SceneInstances, ADeltaThatBreaksTheParentsIsRefused) {
  const SceneState base = with_instances();
  const auto refusal = [&](const std::function<void(wire::StateDelta&)>& edit) {
    wire::StateDelta delta;
    edit(delta);
    SceneState state = base;
    auto applied = apply_delta(state, delta);
    if (applied) return std::string("accepted");
    EXPECT_EQ(state, base) << "refused, but changed: " << applied.error();
    return applied.error();
  };
  const auto changed = [](wire::StateDelta& d, const std::string& id, const InstanceState& i) {
    SceneState one;
    one.instances[id] = i;
    d.add_instances_changed()->CopyFrom(to_snapshot(one).instances(0));
  };
  EXPECT_EQ(refusal([&](auto& d) { d.add_instances_removed("table"); }),
            "delta: instance cup is under table, which does not exist");
  EXPECT_EQ(refusal([&](auto& d) { changed(d, "saucer", instance("saucer", "plate", 0.0)); }),
            "delta: instance saucer is under plate, which does not exist");
  EXPECT_NE(refusal([&](auto& d) {
              changed(d, "table", instance("table", "cup", 0.0));  // the cup is on the table
            }).find("more than 64 instances deep, or under itself"),
            std::string::npos);
  EXPECT_EQ(refusal([&](auto& d) { changed(d, "cup", instance("cup", "cup", 0.0)); }),
            "delta: instance cup is its own parent");
  EXPECT_EQ(refusal([&](auto& d) { changed(d, "a b", instance("x", "", 0.0)); }),
            "delta: an instance's id is not one (1 to 64 of a-z A-Z 0-9 - _ .)");
  EXPECT_EQ(refusal([&](auto& d) { d.add_instances_removed("ghost"); }),
            "delta removes instance ghost, which it cannot: it is not there, changed too, or removed twice");
  EXPECT_EQ(refusal([&](auto& d) {
              InstanceState red = instance("cup", "table", 0.0);
              red.base_color = {2.0, 0.0, 0.0, 1.0};
              changed(d, "cup", red);
            }),
            "delta: instance cup base colour is outside [0, 1.000000]");
  EXPECT_EQ(refusal([&](auto& d) {
              InstanceState lost = instance("cup", "table", 0.0);
              lost.pose.now.position.x = std::nan("");
              changed(d, "cup", lost);
            }),
            "delta: instance cup (now) position has a non-finite coordinate");
  EXPECT_EQ(refusal([&](auto& d) {
              changed(d, "cup", instance("cup", "table", 0.0));
              d.mutable_instances_changed(0)->mutable_pose()->RemoveLast();
            }),
            "delta: instance cup's pose has 19 numbers, not 10 or 20");
  EXPECT_EQ(refusal([&](auto& d) {
              changed(d, "cup", instance("cup", "table", 0.0));
              for (int k = 3; k < 7; ++k) d.mutable_instances_changed(0)->mutable_pose()->Set(k, 1.0);  // rotation
            }),
            "delta: instance cup (now) rotation is not a unit quaternion (norm 2.000000)");
  for (double t : {-1.0, std::nan(""), 2e9}) {
    EXPECT_EQ(refusal([&](auto& d) {
                InstanceState animated = instance("cup", "table", 0.0);
                animated.animation = AnimationTimes{0.0, t};
                changed(d, "cup", animated);
              }),
              "delta: instance cup: its animation's time is outside [0, 1000000000.000000] s")
        << t;
  }
  EXPECT_EQ(refusal([&](auto& d) {
              changed(d, "cup", instance("cup", "table", 0.0));
              changed(d, "lamp", instance("lamp", "", 1.0));
              changed(d, "cup", instance("cup", "", 0.0));
            }),
            "delta changes instance cup twice");
  // Moving the cup off the table, then removing the table, is fine in one delta.
  EXPECT_EQ(refusal([&](auto& d) {
              changed(d, "cup", instance("cup", "lamp", 0.0));
              d.add_instances_removed("table");
            }),
            "accepted");
}

TEST(SceneInstances, AChainOfParentsDeeperThanTheLimitIsRefused) {
  SceneState deep;
  for (std::size_t k = 0; k <= kMaxInstanceDepth; ++k) {
    deep.instances["i" + std::to_string(k)] = instance("box", k == 0 ? "" : "i" + std::to_string(k - 1), 0.0);
  }
  EXPECT_TRUE(from_snapshot(to_snapshot(deep))) << "64 above the deepest: the limit";
  deep.instances["i65"] = instance("box", "i64", 0.0);
  auto refused = from_snapshot(to_snapshot(deep));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error(), "snapshot: instance i65 is more than 64 instances deep, or under itself");
}

TEST(BuiltinScene, CubesPosesAreFiniteUnitAndDeterministic) {
  auto first = builtin_scene("cubes");
  auto second = builtin_scene("cubes");
  ASSERT_TRUE(first.ok()) << first.error();
  ASSERT_TRUE(second.ok()) << second.error();
  const SceneDefinition& a = first.value();
  const SceneDefinition& b = second.value();
  EXPECT_EQ(a.name, "cubes");
  ASSERT_EQ(a.objects.size(), 5u);
  ASSERT_EQ(b.objects.size(), a.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].id, i + 1);
    for (double t : {0.0, 1.0 / 60.0, 0.5, 3.25, 1000.0}) {
      const Pose p = a.objects[i].pose_at(t);
      EXPECT_TRUE(finite(p)) << "cube " << i << " t=" << t;
      EXPECT_NEAR(glm::length(p.rotation), 1.0, 1e-9) << "cube " << i << " t=" << t;
      EXPECT_EQ(p, a.objects[i].pose_at(t)) << "same script, same t";
      EXPECT_EQ(p, b.objects[i].pose_at(t)) << "another instance, same t";
    }
    // They do turn.
    EXPECT_NE(a.objects[i].pose_at(0.0).rotation, a.objects[i].pose_at(0.5).rotation) << "cube " << i;
  }
}

const std::vector<std::string> kBuiltinNames{"cubes", "many-lights", "depth-stack", "moving-square"};

TEST(BuiltinScene, TheFirstFourAreTheKnownScenes) {
  const auto names = builtin_scene_names();
  ASSERT_GE(names.size(), kBuiltinNames.size());
  for (std::size_t i = 0; i < kBuiltinNames.size(); ++i) {
    EXPECT_EQ(names[i], kBuiltinNames[i]);
    EXPECT_TRUE(is_builtin_scene(names[i]));
  }
}

class BuiltinSceneByName : public ::testing::TestWithParam<std::string> {};

TEST_P(BuiltinSceneByName, BuildsFinitePosesDeterministically) {
  auto first = builtin_scene(GetParam());
  auto second = builtin_scene(GetParam());
  ASSERT_TRUE(first.ok()) << first.error();
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_EQ(first.value().name, GetParam());
  ASSERT_FALSE(first.value().objects.empty());
  ASSERT_EQ(first.value().objects.size(), second.value().objects.size());
  for (std::size_t i = 0; i < first.value().objects.size(); ++i) {
    const AnimatedObject& o = first.value().objects[i];
    for (double t : {0.0, 0.75, 2.0 + 1.0 / 60.0}) {
      EXPECT_TRUE(finite(o.pose_at(t))) << o.name << " t=" << t;
      EXPECT_EQ(o.pose_at(t), second.value().objects[i].pose_at(t)) << o.name << " t=" << t;
    }
  }
}

// Every built-in scene must produce poses a node accepts (a braced {} quaternion is
// all zeros, which nodes rightly reject).
TEST_P(BuiltinSceneByName, PosesAreUnitRotationsAcceptedByANode) {
  auto script = builtin_scene(GetParam());
  ASSERT_TRUE(script.ok()) << script.error();
  SceneState state;
  for (const auto& o : script.value().objects) {
    state.objects[o.id] = {o.pose_at(2.0), o.pose_at(2.0 + 1.0 / 60.0)};
    EXPECT_NEAR(glm::length(state.objects[o.id].now.rotation), 1.0, 1e-9) << o.name;
    EXPECT_NEAR(glm::length(state.objects[o.id].next.rotation), 1.0, 1e-9) << o.name;
  }
  // What the master builds, a node can read back: as a snapshot ...
  auto back = from_snapshot(to_snapshot(state));
  ASSERT_TRUE(back.ok()) << back.error();
  EXPECT_EQ(back.value(), state);
  // ... and as a delta.
  SceneState node;
  auto applied = apply_delta(node, make_delta(SceneState{}, state));
  ASSERT_TRUE(applied.ok()) << applied.error();
  EXPECT_EQ(state_hash(node), state_hash(state));
}

INSTANTIATE_TEST_SUITE_P(All, BuiltinSceneByName, ::testing::ValuesIn(kBuiltinNames),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

TEST(BuiltinScene, UnknownNameFails) {
  EXPECT_FALSE(is_builtin_scene("spheres"));
  EXPECT_FALSE(is_builtin_scene(""));
  EXPECT_FALSE(is_builtin_scene("Cubes"));
  auto script = builtin_scene("spheres");
  ASSERT_FALSE(script.ok());
  EXPECT_NE(script.error().find("spheres"), std::string::npos) << script.error();
}

}  // namespace
}  // namespace optique::scene
