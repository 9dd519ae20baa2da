// The live scene applications edit: master/session/live_scene.h.
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "master/session/live_scene.h"

namespace optique::master {
namespace {

session::Transaction transaction(const std::string& text) {
  session::Transaction t;
  EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &t)) << text;
  return t;
}

LiveScene with_torus(LiveSceneLimits limits = {}) {
  LiveScene scene(limits);
  scene.add_asset("torus");
  scene.add_asset("duck");
  return scene;
}

LiveSceneLimits limits_with(std::size_t LiveSceneLimits::*limit, std::size_t value) {
  LiveSceneLimits limits;
  limits.*limit = value;
  return limits;
}

// The refusal of `text`, which must be refused.
Refusal refused(LiveScene& scene, const std::string& text) {
  const auto refusal = scene.apply(transaction(text), 0);
  EXPECT_TRUE(refusal.has_value()) << "accepted: " << text;
  return refusal.value_or(Refusal{});
}

void accept(LiveScene& scene, const std::string& text) {
  const auto refusal = scene.apply(transaction(text), 0);
  ASSERT_FALSE(refusal) << refusal->field << ": " << refusal->reason;
}

TEST(LiveScene, AnInstanceIsPlacedShownAndTinted) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "t1" asset: "torus"
                                     transform { position: [1, 2, 3] rotation: [0, 0, 2, 0] scale: [2] } } })");
  const Instance& t1 = scene.instances().at("t1");
  EXPECT_EQ(t1.asset, "torus");
  EXPECT_EQ(t1.pose.position, glm::dvec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(t1.pose.rotation.y, 1.0) << "the quaternion is normalized";
  EXPECT_EQ(t1.pose.scale, glm::dvec3(2.0));
  EXPECT_TRUE(t1.visible);

  accept(scene, R"(edits { transform { instance: "t1" transform { scale: [1, 2, 3] } } }
                   edits { visible { instance: "t1" visible: false } }
                   edits { factors { instance: "t1" base_color: [1, 0, 0, 0.5] } })");
  const Instance& changed = scene.instances().at("t1");
  EXPECT_EQ(changed.pose.position, glm::dvec3(1, 2, 3)) << "what a transform leaves out keeps its value";
  EXPECT_EQ(changed.pose.scale, glm::dvec3(1, 2, 3));
  EXPECT_FALSE(changed.visible);
  EXPECT_EQ(changed.base_color, glm::dvec4(1, 0, 0, 0.5));
  EXPECT_EQ(changed.emissive, glm::dvec3(1.0));
}

TEST(LiveScene, ATransactionLandsWholeOrNotAtAll) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "t1" asset: "torus" transform { position: [1, 0, 0] } } })");
  const LiveScene before = scene;
  const Refusal refusal = refused(scene, R"(
      edits { transform { instance: "t1" transform { position: [5, 5, 5] } } }
      edits { remove { instance: "t1" } }
      edits { create { instance: "t1" asset: "duck" } }
      edits { create { instance: "t2" asset: "torus" parent: "t1" } }
      edits { create { instance: "t3" asset: "teapot" } })");
  EXPECT_EQ(refusal.edit, 4u);
  EXPECT_EQ(refusal.field, "edits[4].create.asset");
  EXPECT_EQ(refusal.reason, "no asset 'teapot' is loaded");
  EXPECT_EQ(scene.instances(), before.instances());
  EXPECT_EQ(scene.children(""), before.children(""));
  EXPECT_TRUE(scene.children("t1").empty());
}

TEST(LiveScene, NumbersThatPlaceNothingAreRefusedWithTheirField) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "t1" asset: "torus" } })");
  const auto field_of = [&](const std::string& transform) {
    return refused(scene, R"(edits { transform { instance: "t1" transform { )" + transform + " } } }");
  };
  EXPECT_EQ(field_of("position: [0, nan, 0]").field, "edits[0].transform.transform.position[1]");
  EXPECT_EQ(field_of("position: [0, 1e7, 0]").field, "edits[0].transform.transform.position[1]");
  EXPECT_EQ(field_of("position: [0, 1]").reason, "must be [x, y, z] (got 2 numbers)");
  EXPECT_EQ(field_of("rotation: [0, 0, 0, 0]").reason, "has length 0: it is no rotation");
  EXPECT_EQ(field_of("rotation: [1, 0, inf, 0]").field, "edits[0].transform.transform.rotation[2]");
  EXPECT_EQ(field_of("scale: [0]").reason, "must be in [0.0001, 10000] (got 0)");
  EXPECT_EQ(field_of("scale: [1, -1, 1]").field, "edits[0].transform.transform.scale[1]");
  EXPECT_EQ(field_of("scale: [1e5]").field, "edits[0].transform.transform.scale[0]");
  EXPECT_EQ(refused(scene, R"(edits { factors { instance: "t1" base_color: [1, 1, 2, 1] } })").field,
            "edits[0].factors.base_color[2]");
  EXPECT_EQ(refused(scene, R"(edits { factors { instance: "t1" emissive: [1, 1] } })").field,
            "edits[0].factors.emissive");
  Instance untouched;
  untouched.asset = "torus";
  EXPECT_EQ(scene.instances().at("t1"), untouched);
}

TEST(LiveScene, IdsAreCheckedAndMustExist) {
  LiveScene scene = with_torus();
  EXPECT_EQ(refused(scene, R"(edits { create { asset: "torus" } })").reason, "is needed");
  EXPECT_EQ(refused(scene, R"(edits { create { instance: "a b" asset: "torus" } })").reason,
            "may only use letters, digits, '-', '_' and '.'");
  EXPECT_EQ(refused(scene, "edits { create { instance: \"" + std::string(65, 'x') + "\" asset: \"torus\" } }").field,
            "edits[0].create.instance");
  EXPECT_EQ(refused(scene, R"(edits { visible { instance: "ghost" visible: true } })").reason, "no instance 'ghost'");
  EXPECT_EQ(refused(scene, R"(edits { create { instance: "a" asset: "torus" parent: "ghost" } })").field,
            "edits[0].create.parent");
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } })");
  EXPECT_EQ(refused(scene, R"(edits { create { instance: "a" asset: "duck" } })").reason, "'a' exists already");
  accept(scene, R"(edits { create { instance: "Lamp-2_b.v1" asset: "duck" } })");  // every kind of character
  const Refusal empty = refused(scene, "edits { }");
  EXPECT_EQ(empty.field, "edits[0]");
  EXPECT_EQ(empty.reason, "is empty or of a kind this master does not know");
}

TEST(LiveScene, AnInstanceCannotHoldItself) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } }
                   edits { create { instance: "b" asset: "torus" parent: "a" } }
                   edits { create { instance: "c" asset: "torus" parent: "b" } })");
  EXPECT_EQ(refused(scene, R"(edits { parent { instance: "a" parent: "c" } })").reason,
            "'c' is 'a' or under it: an instance cannot hold itself");
  EXPECT_EQ(refused(scene, R"(edits { parent { instance: "b" parent: "b" } })").field, "edits[0].parent.parent");
  accept(scene, R"(edits { parent { instance: "c" parent: "" } })");
  EXPECT_EQ(scene.instances().at("c").parent, "");
  EXPECT_EQ(scene.children("b").size(), 0u);
  EXPECT_EQ(scene.children("").size(), 2u);
}

TEST(LiveScene, RemovingAnInstanceRemovesWhatItHolds) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } }
                   edits { create { instance: "b" asset: "torus" parent: "a" } }
                   edits { create { instance: "c" asset: "torus" parent: "b" } }
                   edits { create { instance: "d" asset: "duck" } })");
  accept(scene, R"(edits { remove { instance: "a" } })");
  ASSERT_EQ(scene.instances().size(), 1u);
  EXPECT_EQ(scene.instances().count("d"), 1u);
  EXPECT_TRUE(scene.children("a").empty());
  EXPECT_TRUE(scene.children("b").empty());
  // The ids are free again.
  accept(scene, R"(edits { create { instance: "b" asset: "torus" parent: "d" } })");
}

TEST(LiveScene, TheChainOfParentsIsBounded) {
  LiveScene scene = with_torus(limits_with(&LiveSceneLimits::max_depth, 2));
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } }
                   edits { create { instance: "b" asset: "torus" parent: "a" } }
                   edits { create { instance: "c" asset: "torus" parent: "b" } })");
  EXPECT_EQ(refused(scene, R"(edits { create { instance: "d" asset: "torus" parent: "c" } })").reason,
            "would put 'd' more than 2 instances deep");
  // Moving a holder moves what it holds: b (with c) under a new x under a.
  accept(scene, R"(edits { create { instance: "x" asset: "torus" } })");
  EXPECT_EQ(refused(scene, R"(edits { parent { instance: "b" parent: "c" } })").field, "edits[0].parent.parent");
  EXPECT_EQ(refused(scene, R"(edits { parent { instance: "a" parent: "x" } })").reason,
            "would put 'c' more than 2 instances deep");
  accept(scene, R"(edits { parent { instance: "c" parent: "x" } })");
}

TEST(LiveScene, EachFrameHasABudgetOfEdits) {
  LiveScene scene = with_torus(limits_with(&LiveSceneLimits::max_edits_per_frame, 3));
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } }
                   edits { create { instance: "b" asset: "torus" } })");
  const Refusal over = refused(scene, R"(edits { visible { instance: "a" visible: false } }
                                         edits { visible { instance: "b" visible: false } })");
  EXPECT_EQ(over.field, "edits");
  EXPECT_EQ(over.reason, "2 edits, but 1 of this frame's 3 are left: send the rest in a later frame");
  EXPECT_TRUE(scene.instances().at("a").visible);
  scene.begin_frame();
  accept(scene, R"(edits { visible { instance: "a" visible: false } }
                   edits { visible { instance: "b" visible: false } })");
}

TEST(LiveScene, TheNumberOfInstancesIsBounded) {
  LiveScene scene = with_torus(limits_with(&LiveSceneLimits::max_instances, 2));
  accept(scene, R"(edits { create { instance: "a" asset: "torus" } }
                   edits { create { instance: "b" asset: "torus" } })");
  EXPECT_EQ(refused(scene, R"(edits { create { instance: "c" asset: "torus" } })").reason,
            "the scene holds 2 instances, the most it may");
  accept(scene, R"(edits { remove { instance: "a" } } edits { create { instance: "c" asset: "torus" } })");
}

TEST(LiveScene, TheNavigationIsSetWholeAndUniformlyScaled) {
  LiveScene scene = with_torus();
  EXPECT_EQ(scene.navigation().sets, 0u);
  accept(scene, R"(edits { navigation { transform { position: [10, 0, -5] rotation: [0, 0, 3, 0] scale: [2] } } })");
  EXPECT_EQ(scene.navigation().sets, 1u);
  EXPECT_EQ(scene.navigation().pose.position, glm::dvec3(10, 0, -5));
  EXPECT_DOUBLE_EQ(scene.navigation().pose.rotation.y, 1.0);
  EXPECT_EQ(scene.navigation().pose.scale, glm::dvec3(2.0));

  const Refusal stretched = refused(scene, R"(edits { navigation { transform { scale: [1, 2, 1] } } })");
  EXPECT_EQ(stretched.field, "edits[0].navigation.transform.scale");
  EXPECT_EQ(stretched.reason, "must be the same on every axis: give [s]");
  EXPECT_EQ(refused(scene, R"(edits { navigation { transform { position: [nan, 0, 0] } } })").field,
            "edits[0].navigation.transform.position[0]");

  // A later edit's refusal takes the navigation back too.
  refused(scene, R"(edits { navigation { transform { position: [0, 0, 0] } } }
                    edits { visible { instance: "none" visible: false } })");
  EXPECT_EQ(scene.navigation().pose.position, glm::dvec3(10, 0, -5));
  EXPECT_EQ(scene.navigation().sets, 1u);
  // Set again where it is: still a set (a flown viewer comes back).
  accept(scene, R"(edits { navigation { transform { position: [10, 0, -5] } } })");
  EXPECT_EQ(scene.navigation().sets, 2u);

  scene::SceneState state;
  put_live(scene, 0, state);
  EXPECT_EQ(state.navigation.now, scene.navigation().pose);
  EXPECT_EQ(state.navigation.next, scene.navigation().pose);
  const session::SceneContents contents = scene_contents(scene, 7);
  ASSERT_EQ(contents.navigation().position_size(), 3);
  EXPECT_EQ(contents.navigation().position(0), 10.0);
  EXPECT_EQ(contents.navigation().scale(2), 2.0);
}

TEST(LiveScene, LightsAreSwitchedOverTheConfigsSwitches) {
  LiveScene scene = with_torus();
  EXPECT_EQ(refused(scene, R"(edits { light { light: 0 on: false } })").reason,
            "the scene has no point lights, and no light 0 was added");
  scene.set_light_count(3);
  const Refusal beyond = refused(scene, R"(edits { light { light: 3 on: false } })");
  EXPECT_EQ(beyond.field, "edits[0].light.light");
  EXPECT_EQ(beyond.reason, "the scene's point lights are 0 to 2, and no light 3 was added");
  refused(scene, R"(edits { light { light: 1 on: false } } edits { remove { instance: "none" } })");
  EXPECT_TRUE(scene.light_switches().empty()) << "a refused transaction switches nothing";
  accept(scene, R"(edits { light { light: 1 on: false } } edits { light { light: 2 on: true } })");

  scene::SceneState state;
  state.lights_off = {0, 2};  // the config's script switched 0 and 2 off
  put_live(scene, 0, state);
  EXPECT_EQ(state.lights_off, (std::set<std::uint32_t>{0, 1})) << "1 switched off, 2 on; 0 as the script has it";
  const session::SceneContents contents = scene_contents(scene, 0);
  EXPECT_EQ(contents.light_count(), 3u);
  ASSERT_EQ(contents.lights_size(), 2);
  EXPECT_EQ(contents.lights(0).light(), 1u);
  EXPECT_FALSE(contents.lights(0).on());
  EXPECT_TRUE(contents.lights(1).on());
}

// Point lights added after the scene's own: placed, changed field by field,
// switched, removed with their switch, bounded, and put into each frame's
// state; a refused transaction leaves them as they were.
TEST(LiveScene, PointLightsAreAddedChangedSwitchedAndRemoved) {
  LiveSceneLimits limits;
  limits.max_point_lights = 3;
  LiveScene scene = with_torus(limits);
  scene.set_light_count(2);
  accept(scene, R"(edits { point_light { light: 2 position: [0, 2, -1] } })");
  ASSERT_EQ(scene.point_lights().size(), 1u);
  EXPECT_EQ(scene.point_lights().at(2), (scene::PointLightState{{0, 2, -1}, {1, 1, 1}, 1}));
  accept(scene, R"(edits { point_light { light: 2 colour: [1, 0.5, 0] intensity: 3 } })");
  EXPECT_EQ(scene.point_lights().at(2), (scene::PointLightState{{0, 2, -1}, {1, 0.5, 0}, 3}));
  accept(scene, R"(edits { point_light { light: 4 position: [1, 1, 1] } } edits { light { light: 4 on: false } })");
  scene::SceneState state;
  put_live(scene, 0, state);
  EXPECT_EQ(state.point_lights, scene.point_lights());
  EXPECT_EQ(state.lights_off, (std::set<std::uint32_t>{4}));
  const session::SceneContents contents = scene_contents(scene, 0);
  ASSERT_EQ(contents.point_lights_size(), 2);
  EXPECT_EQ(contents.point_lights(0).light(), 2u);
  EXPECT_EQ(contents.point_lights(0).colour(1), 0.5);
  EXPECT_EQ(contents.point_lights(0).intensity(), 3.0);
  EXPECT_EQ(contents.max_point_lights(), 3u);

  const auto why = [&](const std::string& text) {
    const Refusal r = refused(scene, text);
    return r.field + ": " + r.reason;
  };
  // Each edit, and the field and reason it is refused with.
  const std::vector<std::pair<std::string, std::string>> refusals{
      {R"(point_light { light: 1 position: [0, 0, 0] })",
       "point_light.light: lights added take the indices 2 to 4, after the scene's own (got 1)"},
      {R"(point_light { light: 5 position: [0, 0, 0] })",
       "point_light.light: lights added take the indices 2 to 4, after the scene's own (got 5)"},
      {R"(point_light { light: 3 colour: [1, 1, 1] })", "point_light.position: is needed to add a light"},
      {R"(point_light { light: 3 position: [0, 0] })", "point_light.position: must be [x, y, z] (got 2 numbers)"},
      {R"(point_light { light: 2 position: [0, nan, 0] })",
       "point_light.position[1]: must be in [-1e+06, 1e+06] (got nan)"},
      {R"(point_light { light: 2 colour: [0, 2000, 0] })", "point_light.colour[1]: must be in [0, 1000] (got 2000)"},
      {R"(point_light { light: 2 intensity: -1 })", "point_light.intensity: must be in [0, 1e+06] (got -1)"},
      {R"(remove_point_light { light: 3 })", "remove_point_light.light: no light 3 was added"},
      {R"(remove_point_light { light: 0 })", "remove_point_light.light: no light 0 was added"},
  };
  for (const auto& [edit, says] : refusals) EXPECT_EQ(why("edits { " + edit + " }"), "edits[0]." + says);
  // Refused whole: the light moved and removed first are as they were.
  const auto lights = scene.point_lights();
  const auto switches = scene.light_switches();
  EXPECT_EQ(why(R"(edits { point_light { light: 2 position: [5, 5, 5] } } edits { remove_point_light { light: 4 } }
                  edits { point_light { light: 3 position: [0, 0, 0] } } edits { point_light { light: 9 } })"),
            "edits[3].point_light.light: lights added take the indices 2 to 4, after the scene's own (got 9)");
  EXPECT_EQ(scene.point_lights(), lights);
  EXPECT_EQ(scene.light_switches(), switches);

  accept(scene, R"(edits { point_light { light: 3 position: [0, 0, 0] } })");
  EXPECT_EQ(scene.point_lights().size(), 3u);
  // Removed: its switch goes with it, and the index may be used again.
  accept(scene, R"(edits { remove_point_light { light: 4 } })");
  EXPECT_TRUE(scene.light_switches().empty());
  scene::SceneState next;  // as the scene's authority makes each frame's
  put_live(scene, 1, next);
  EXPECT_EQ(next.point_lights.size(), 2u);
  EXPECT_TRUE(next.lights_off.empty());
  EXPECT_EQ(why(R"(edits { light { light: 4 on: true } })"),
            "edits[0].light.light: the scene's point lights are 0 to 1, and no light 4 was added");
  accept(scene, R"(edits { point_light { light: 4 position: [2, 2, 2] } })");
}

// put_live into a state that holds instances already: the state it leaves is
// the one a fresh state gets, whether it held more instances, fewer, or others
// with other fields.
TEST(LiveScene, PutLiveIntoAStateThatHeldOtherInstancesGivesTheSameState) {
  LiveScene scene = with_torus();
  accept(scene, R"(edits { create { instance: "a" asset: "torus" transform { position: [1, 2, 3] } } }
                   edits { create { instance: "b" asset: "torus" parent: "a" hidden: true } }
                   edits { create { instance: "c" asset: "torus" } }
                   edits { animation { instance: "c" playing: false seek: 2 } })");
  scene::SceneState fresh;
  put_live(scene, 5, fresh);
  ASSERT_EQ(fresh.instances.size(), 3u);
  for (std::size_t held : {0u, 1u, 3u, 7u}) {
    scene::SceneState reused;
    for (std::size_t i = 0; i < held; ++i) {
      scene::InstanceState other;
      other.asset = "a-much-longer-asset-name-than-torus";
      other.parent = "someone-else";
      other.visible = false;
      other.base_color = {0.5, 0.5, 0.5, 0.5};
      other.animation = scene::AnimationTimes{9.0, 9.5};
      reused.instances["z" + std::to_string(i)] = other;
    }
    put_live(scene, 5, reused);
    EXPECT_EQ(reused.instances, fresh.instances) << held << " held";
    EXPECT_EQ(scene::state_hash(reused), scene::state_hash(fresh)) << held << " held";
  }
}

TEST(LiveScene, OfAnInstallationsSceneHasItsAssetAndLights) {
  scene::SceneDefinition definition;
  definition.asset_id = "cubes";
  definition.lights.resize(2);
  LiveScene scene = LiveScene::of(definition, {}, 60.0);
  EXPECT_TRUE(scene.has_asset("cubes"));
  accept(scene, R"(edits { light { light: 1 on: false } })");
  EXPECT_FALSE(scene.apply(transaction(R"(edits { light { light: 2 on: false } })"), 0)->reason.empty());
}

// An instance's own animation clock: from where the scene's time has its
// asset's animations in the frame it is set for, paused, played and sought;
// each frame's state carries its times, now and next; a refusal leaves it.
TEST(LiveScene, AnInstancesAnimationsArePlayedPausedAndSought) {
  LiveScene scene(LiveSceneLimits{}, 0.1);  // frames 0.1 s apart
  scene.add_asset("torus");
  const auto times = [&](std::uint64_t frame) {
    scene::SceneState state;
    put_live(scene, frame, state);
    return state.instances.at("t").animation;
  };
  ASSERT_FALSE(scene.apply(transaction(R"(edits { create { instance: "t" asset: "torus" } })"), 5));
  EXPECT_FALSE(times(10)) << "the scene's time until an application sets its clock";

  // Paused in frame 10: where the scene's time is then, 1 s.
  ASSERT_FALSE(scene.apply(transaction(R"(edits { animation { instance: "t" playing: false } })"), 10));
  EXPECT_DOUBLE_EQ(times(10)->now, 1.0);
  EXPECT_DOUBLE_EQ(times(25)->now, 1.0);
  EXPECT_DOUBLE_EQ(times(25)->next, 1.0);
  // Played again in frame 30, from 1 s on.
  ASSERT_FALSE(scene.apply(transaction(R"(edits { animation { instance: "t" playing: true } })"), 30));
  EXPECT_DOUBLE_EQ(times(30)->now, 1.0);
  EXPECT_DOUBLE_EQ(times(40)->now, 2.0);
  EXPECT_DOUBLE_EQ(times(40)->next, 2.1);
  // Sought to 7 s in frame 40: it plays on from there.
  ASSERT_FALSE(scene.apply(transaction(R"(edits { animation { instance: "t" seek: 7 } })"), 40));
  EXPECT_DOUBLE_EQ(times(40)->now, 7.0);
  EXPECT_DOUBLE_EQ(times(45)->now, 7.5);
  // Sought and paused at once.
  ASSERT_FALSE(scene.apply(transaction(R"(edits { animation { instance: "t" seek: 0.25 playing: false } })"), 50));
  EXPECT_DOUBLE_EQ(times(90)->next, 0.25);
  const session::SceneContents contents = scene_contents(scene, 90);
  ASSERT_TRUE(contents.instances(0).has_animation());
  EXPECT_FALSE(contents.instances(0).animation().playing());
  EXPECT_EQ(contents.instances(0).animation().position(), 0.25);

  for (const char* text :
       {R"(edits { animation { instance: "t" seek: -1 } })", R"(edits { animation { instance: "t" seek: nan } })",
        R"(edits { animation { instance: "t" seek: 2e6 } })"}) {
    const Refusal wrong = refused(scene, text);
    EXPECT_EQ(wrong.field, "edits[0].animation.seek") << text;
    EXPECT_NE(wrong.reason.find("must be in [0, 1e+06] seconds"), std::string::npos) << wrong.reason;
  }
  EXPECT_EQ(refused(scene, R"(edits { animation { instance: "t" } })").reason, "give playing, seek or both");
  EXPECT_EQ(refused(scene, R"(edits { animation { instance: "ghost" playing: true } })").reason, "no instance 'ghost'");
  refused(scene, R"(edits { animation { instance: "t" playing: true } } edits { remove { instance: "ghost" } })");
  EXPECT_FALSE(scene.instances().at("t").animation->playing) << "a refused transaction changes no clock";

  // A new run of the master (from its journal): the clocks go on from where
  // they were at the last transaction, from frame 0.
  ASSERT_FALSE(scene.apply(transaction(R"(edits { animation { instance: "t" playing: true } })"), 60));
  scene.begin_run(80);
  EXPECT_DOUBLE_EQ(times(0)->now, 0.25 + 2.0);
  EXPECT_DOUBLE_EQ(times(10)->now, 0.25 + 3.0);
}

}  // namespace
}  // namespace optique::master
