// Stacked groups: the checks check-config makes on lights and focus pairs
// (master/run/stacked_groups.h, common/config/across.cpp) and the light plan.

#include "master/run/stacked_groups.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "config/load.h"
#include "config/problem.h"
#include "master/run/scene_authority.h"
#include "scene/builtin.h"

namespace optique::master {
namespace {

// Three stacked projectors on one screen sharing 20 lights; each test changes
// the projectors' content by text.
std::string stacked(const std::string& a, const std::string& b, const std::string& c,
                    const std::string& extra_projector = "") {
  return R"json({
  "screens": [{"id": "front", "origin": [-1.6, 0.3, 0.0], "right": [1, 0, 0], "up": [0, 1, 0],
               "width": 3.2, "height": 1.8}],
  "projectors": [
    {"id": "a", "width": 320, "height": 180, "screen": "front", "content": )json" +
         a + R"json(},
    {"id": "b", "width": 320, "height": 180, "screen": "front", "content": )json" +
         b + R"json(},
    {"id": "c", "width": 640, "height": 360, "screen": "front", "content": )json" +
         c + "}" + extra_projector + R"json(
  ],
  "viewer": {"eye": [0.0, 1.2, 2.0]},
  "scene": {"builtin": "many-lights"}
})json";
}

config::Installation parsed(const std::string& json) {
  auto installation = config::parse_installation(json, "stacked.json", ::testing::TempDir());
  EXPECT_TRUE(installation) << (installation ? "" : installation.error());
  return installation ? installation.value() : config::Installation{};
}

std::string light_problems(const std::string& json) {
  return config::describe_problems(check_lighting_groups(parsed(json), 20), "stacked.json");
}

const std::string kA = R"({"role": "lights", "lights": "0-6", "ambient": true})";
const std::string kB = R"({"role": "lights", "lights": "7-13"})";
const std::string kC = R"({"role": "lights", "lights": "14-19"})";

TEST(StackedGroups, ASplitOfEveryLightOnceIsAccepted) {
  EXPECT_EQ(light_problems(stacked(kA, kB, kC)), "");
  const auto shares = listed_shares(parsed(stacked(kA, kB, kC)), 20);
  ASSERT_EQ(shares.size(), 3u);
  EXPECT_EQ(shares.at(0).lights.size(), 7u);
  EXPECT_TRUE(shares.at(0).ambient);
  EXPECT_EQ(shares.at(2).lights.front(), 14u);
  EXPECT_FALSE(shares.at(2).ambient);
}

TEST(StackedGroups, EachMistakeHasItsOwnMessage) {
  const std::string missing = light_problems(stacked(kA, kB, R"({"role": "lights", "lights": "14-18"})"));
  EXPECT_NE(missing.find("projectors[0].content.lights: the stacked group on screen 'front' (eye mono) draws no "
                         "light 19 of the scene's 20"),
            std::string::npos)
      << missing;

  const std::string twice = light_problems(stacked(kA, R"({"role": "lights", "lights": "6-13"})", kC));
  EXPECT_NE(twice.find("projectors[1].content.lights: light 6 is drawn twice in the stacked group on screen 'front' "
                       "(eye mono), by 'a' and 'b'"),
            std::string::npos)
      << twice;

  const std::string two_ambient =
      light_problems(stacked(kA, R"({"role": "lights", "lights": "7-13", "ambient": true})", kC));
  EXPECT_NE(two_ambient.find("ambient and emissive light are carried twice in the stacked group on screen 'front' "
                             "(eye mono), by 'a' and 'b'"),
            std::string::npos)
      << two_ambient;

  const std::string no_ambient = light_problems(stacked(R"({"role": "lights", "lights": "0-6"})", kB, kC));
  EXPECT_NE(no_ambient.find("no projector of the stacked group on screen 'front' (eye mono) carries ambient"),
            std::string::npos)
      << no_ambient;

  const std::string unknown = light_problems(stacked(kA, kB, R"({"role": "lights", "lights": "14-24"})"));
  EXPECT_NE(unknown.find("projectors[2].content.lights: "), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("20 lights"), std::string::npos) << unknown;

  const std::string mixed = light_problems(stacked(kA, kB, R"({"role": "lights", "lights": "auto"})"));
  EXPECT_NE(mixed.find("mixes \"auto\" with listed lights"), std::string::npos) << mixed;
}

TEST(StackedGroups, TilesOfOneLayerShareTheirLights) {
  // Two tiles showing the same lights are one layer: their lights count once.
  const std::string tile = R"(,
    {"id": "a2", "width": 320, "height": 180, "screen": "front", "region": {"x": 1.6, "y": 0, "width": 1.6,
     "height": 1.8}, "content": {"role": "lights", "lights": "0-6", "ambient": true}})";
  EXPECT_EQ(light_problems(stacked(kA, kB, kC, tile)), "");
}

TEST(StackedGroups, AFocusOrDefocusProjectorNeedsItsPartner) {
  std::string json = stacked(R"({"role": "defocus"})", R"({"role": "full"})", R"({"role": "full"})");
  json.insert(json.find("\"viewer\""), R"("depth_of_field": {"focal_depth": 2.0}, )");
  auto installation = config::parse_installation(json, "dof.json", ::testing::TempDir());
  ASSERT_FALSE(installation);
  EXPECT_NE(installation.error().find("dof.json: projectors[0].content.role: a 'defocus' projector needs a 'focus' "
                                      "partner on screen 'front' for the same eye, and 'a' has none"),
            std::string::npos)
      << installation.error();

  auto no_depth = stacked(R"({"role": "focus"})", R"({"role": "defocus"})", R"({"role": "full"})");
  auto refused = config::parse_installation(no_depth, "dof.json", ::testing::TempDir());
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("depth_of_field: focus/defocus projectors need the focal depth"), std::string::npos)
      << refused.error();
}

// A depth of field relates to the projectors: set where no pair shows it, it is
// a mistake (a copied block, a role changed), said at the section, and alone.
TEST(StackedGroups, ADepthOfFieldWithoutAFocusPairIsRefused) {
  std::string json = stacked(R"({"role": "full"})", R"({"role": "full"})", R"({"role": "full"})");
  json.insert(json.find("\"viewer\""), R"("depth_of_field": {"focal_depth": 2.0}, )");
  auto installation = config::parse_installation(json, "dof.json", ::testing::TempDir());
  ASSERT_FALSE(installation);
  EXPECT_EQ(installation.error(), "dof.json: depth_of_field: set, but no projector has role 'focus' or 'defocus'");
}

TEST(LightPlan, AutomaticGroupsShareAmongTheNodesThatAreUp) {
  const std::string autolights = R"({"role": "lights", "lights": "auto"})";
  const config::Installation installation = parsed(stacked(autolights, autolights, autolights));
  EXPECT_EQ(light_problems(stacked(autolights, autolights, autolights)), "");
  auto scene = scene::builtin_scene("many-lights");
  ASSERT_TRUE(scene);
  const SceneAuthority authority(scene.value().objects, installation.viewer, 60.0);
  const scene::SceneState state = authority.state_at_frame(0);
  LightPlan plan(installation, scene.value());
  EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
  std::size_t total = 0;
  int ambient = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_NE(plan.share(i), nullptr);
    total += plan.share(i)->lights.size();
    ambient += plan.share(i)->ambient ? 1 : 0;
  }
  EXPECT_EQ(total, 20u);
  EXPECT_EQ(ambient, 1);
  // 'c' has four times the pixels of 'a' or 'b': it gets the fewest lights.
  EXPECT_LT(plan.share(2)->lights.size(), plan.share(0)->lights.size());
  // Nothing moved: no new split.
  EXPECT_FALSE(plan.rebalance({true, true, true}, state, state.eye_now, false));

  // 'b' goes: its lights go to the others, none is lost.
  EXPECT_TRUE(plan.rebalance({true, false, true}, state, state.eye_now, true));
  EXPECT_TRUE(plan.share(1)->lights.empty());
  EXPECT_FALSE(plan.share(1)->ambient);
  EXPECT_EQ(plan.share(0)->lights.size() + plan.share(2)->lights.size(), 20u);
  EXPECT_TRUE(plan.share(0)->ambient || plan.share(2)->ambient);
}

TEST(LightPlan, LightsThatAreOffGoToNobodyAndComeBackWhenOn) {
  const std::string autolights = R"({"role": "lights", "lights": "auto"})";
  const config::Installation installation = parsed(stacked(autolights, autolights, autolights));
  auto scene = scene::builtin_scene("many-lights");
  ASSERT_TRUE(scene);
  const SceneAuthority authority(scene.value().objects, installation.viewer, 60.0);
  scene::SceneState state = authority.state_at_frame(0);
  LightPlan plan(installation, scene.value());
  ASSERT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));

  const auto drawn = [&] {
    std::multiset<std::uint32_t> lights;
    for (std::size_t i = 0; i < 3; ++i) lights.insert(plan.share(i)->lights.begin(), plan.share(i)->lights.end());
    return lights;
  };
  state.lights_off = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13};
  EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
  EXPECT_EQ(drawn(), (std::multiset<std::uint32_t>{14, 15, 16, 17, 18, 19}));  // each shining light once

  state.lights_off = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19};
  EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
  EXPECT_TRUE(drawn().empty());
  int ambient = 0;
  for (std::size_t i = 0; i < 3; ++i) ambient += plan.share(i)->ambient ? 1 : 0;
  EXPECT_EQ(ambient, 1) << "with every light off, the ambient still needs its carrier";

  state.lights_off.clear();
  EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
  const std::multiset<std::uint32_t> all = drawn();
  EXPECT_EQ(all.size(), 20u);
  EXPECT_EQ(std::set<std::uint32_t>(all.begin(), all.end()).size(), 20u);
}

// The lights applications add: an automatic group shares them out with the
// scene's (each once, none when off), a group whose config lists its lights
// gives them to the projector that carries the ambient light; removed, they go.
TEST(LightPlan, LightsAddedAreSharedOutLikeTheScenesOwn) {
  auto scene = scene::builtin_scene("many-lights");
  ASSERT_TRUE(scene);
  const auto drawn = [](const LightPlan& plan) {
    std::multiset<std::uint32_t> lights;
    for (std::size_t i = 0; i < 3; ++i) lights.insert(plan.share(i)->lights.begin(), plan.share(i)->lights.end());
    return lights;
  };
  const std::string autolights = R"({"role": "lights", "lights": "auto"})";
  for (const bool automatic : {true, false}) {
    SCOPED_TRACE(automatic ? "auto" : "listed");
    const config::Installation installation =
        automatic ? parsed(stacked(autolights, autolights, autolights)) : parsed(stacked(kA, kB, kC));
    const SceneAuthority authority(scene.value().objects, installation.viewer, 60.0);
    scene::SceneState state = authority.state_at_frame(0);
    LightPlan plan(installation, scene.value());
    plan.rebalance({true, true, true}, state, state.eye_now, true);
    ASSERT_EQ(drawn(plan).size(), 20u);

    // Two added in front of the screen, one of them off; index 21 is left empty.
    state.point_lights[20] = {{0.0, 1.2, 0.5}, {1.0, 1.0, 1.0}, 2.0};
    state.point_lights[22] = {{0.5, 1.0, 0.5}, {1.0, 1.0, 1.0}, 2.0};
    state.lights_off = {22};
    EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
    std::multiset<std::uint32_t> all = drawn(plan);
    EXPECT_EQ(all.count(20), 1u);
    EXPECT_EQ(all.count(21), 0u);
    if (automatic) {
      EXPECT_EQ(all.size(), 21u);
      EXPECT_EQ(all.count(22), 0u) << "off: drawn by nobody";
    } else {
      // Listed: the ambient carrier 'a' draws both (the renderer skips one that is off).
      EXPECT_EQ(plan.share(0)->lights, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6, 20, 22}));
      EXPECT_EQ(plan.share(1)->lights.size(), 7u);
    }
    state.point_lights.erase(20);
    state.point_lights.erase(22);
    state.lights_off.clear();
    EXPECT_TRUE(plan.rebalance({true, true, true}, state, state.eye_now, true));
    all = drawn(plan);
    EXPECT_EQ(all.size(), 20u);
    EXPECT_EQ(all.count(20), 0u);
  }
}

}  // namespace
}  // namespace optique::master
