// Lights switched on and off over a show (master/run/light_switches.h, checked as the
// config is read and again against the scene): what check-config refuses, and
// which lights are off when.

#include "master/run/light_switches.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "config/load.h"

namespace optique::master {
namespace {

Result<config::Installation> show_with(const std::string& switches) {
  const std::string json =
      R"({"screens": [{"id": "s", "origin": [0, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0], "width": 2, "height": 1}],
          "projectors": [{"id": "p", "width": 64, "height": 32, "screen": "s"}], "viewer": {"eye": [1, 0.5, 2]},
          "scene": {"builtin": "many-lights", "light_switches": [)" +
      switches + "]}}";
  return config::parse_installation(json, "show.json", ::testing::TempDir());
}

config::SceneSource scene_with(const std::string& switches) {
  auto show = show_with(switches);
  EXPECT_TRUE(show.ok()) << show.error();
  return show.ok() ? show.value().scene : config::SceneSource{};
}

// What check-config says of these switches in a scene of 20 lights.
std::string problems_of(const std::string& switches) {
  auto show = show_with(switches);
  if (!show) return show.error();
  return config::describe_problems(LightSwitches::check(show.value().scene, 20), "show.json");
}

TEST(LightSwitches, LightsGoDarkAndComeBackAtTheirTimes) {
  const std::string show = R"({"time": 1.0, "off": "10-19"}, {"time": 2.0, "on": "10-14", "off": "0"},
                              {"time": 2.0, "on": "15-19"})";
  ASSERT_EQ(problems_of(show), "");
  const LightSwitches switches = LightSwitches::from_config(scene_with(show));
  EXPECT_TRUE(switches.off_at(0.0).empty());
  EXPECT_TRUE(switches.off_at(0.999).empty());
  EXPECT_EQ(switches.off_at(1.0), (std::set<std::uint32_t>{10, 11, 12, 13, 14, 15, 16, 17, 18, 19}));
  EXPECT_EQ(switches.off_at(1.5).size(), 10u);
  EXPECT_EQ(switches.off_at(2.0), std::set<std::uint32_t>{0});  // both switches at 2 s
  EXPECT_EQ(switches.off_at(100.0), std::set<std::uint32_t>{0});
  EXPECT_TRUE(LightSwitches{}.off_at(5.0).empty());
}

TEST(LightSwitches, ASwitchLandsOnTheFrameOfItsTime) {
  // Frame 120 at 60 Hz is at 120 · 16 666 666 ns = 1.99999992 s: that is 2 s.
  const LightSwitches switches = LightSwitches::from_config(scene_with(R"({"time": 2.0, "off": "3"})"));
  EXPECT_EQ(switches.off_at(120 * 16'666'666 * 1e-9), std::set<std::uint32_t>{3});
  EXPECT_TRUE(switches.off_at(119 * 16'666'666 * 1e-9).empty());
}

TEST(LightSwitches, EachMistakeHasItsOwnMessage) {
  EXPECT_EQ(problems_of(R"({"time": -1, "off": "3"})"),
            "show.json: scene.light_switches[0].time: must be a finite number of seconds ≥ 0 (got -1)");
  EXPECT_EQ(problems_of(R"({"time": 2, "off": "3"}, {"time": 1, "on": "3"})"),
            "show.json: scene.light_switches[1].time: switches must be in time order: 1 s comes before the switch "
            "above it at 2 s");
  // Out of order, "is not off" would blame the first switch for the second's
  // place: only the order is reported.
  EXPECT_EQ(problems_of(R"({"time": 2, "on": "3"}, {"time": 1, "off": "3"})"),
            "show.json: scene.light_switches[1].time: switches must be in time order: 1 s comes before the switch "
            "above it at 2 s");
  EXPECT_EQ(problems_of(R"({"time": 1})"),
            "show.json: scene.light_switches[0]: switches nothing: give the lights that go \"off\" or come \"on\"");
  EXPECT_EQ(problems_of(R"({"time": 1, "off": "18-22"})"),
            "show.json: scene.light_switches[0].off: lights 20-22 do not exist: the scene has 20 lights (0-19)");
  EXPECT_NE(problems_of(R"({"time": 1, "on": "x"})").find("show.json: scene.light_switches[0].on: "),
            std::string::npos);
  EXPECT_EQ(problems_of(R"({"time": 1, "off": "3-5"}, {"time": 2, "off": "5, 6"})"),
            "show.json: scene.light_switches[1].off: light 5 is off already: a switch that changes nothing is "
            "probably a typo");
  EXPECT_EQ(problems_of(R"({"time": 1, "on": "2"})"),
            "show.json: scene.light_switches[0].on: light 2 is not off: a switch that changes nothing is probably "
            "a typo");
  EXPECT_EQ(problems_of(R"({"time": 1, "off": "2", "on": "2"})"),
            "show.json: scene.light_switches[0].on: light 2 is not off: a switch that changes nothing is probably "
            "a typo");
}

}  // namespace
}  // namespace optique::master
