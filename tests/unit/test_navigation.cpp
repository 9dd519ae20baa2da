// The viewer's travel through the world: master/navigation.h.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "master/navigation.h"
#include "scene/definition.h"

namespace optique::master {
namespace {

constexpr clock::Nanos kPeriod = 10'000'000;  // 100 Hz: 0.01 s a frame

config::Navigation flystick_navigation() {
  config::Navigation n;
  n.mode = config::NavigationMode::flystick;
  n.flystick = 1;
  n.speed = 2.0;        // m/s
  n.turn_speed = 90.0;  // degrees/s
  n.reset_button = 3;
  n.dead_zone = 0.1;
  return n;
}

// Flystick `id` seen at the tracker's origin, unturned (pointing along -z),
// with a joystick at (x, y) and button `pressed` down (if any).
tracking::FlystickSample stick(std::uint32_t id, double x, double y, int pressed = -1, bool seen = true,
                               clock::Nanos arrival = 1) {
  tracking::FlystickSample s;
  s.arrival = arrival;
  s.id = id;
  s.seen = seen;
  s.buttons.assign(6, false);
  if (pressed >= 0) s.buttons[static_cast<std::size_t>(pressed)] = true;
  s.controllers = {x, y};
  return s;
}

glm::dvec3 to_world(const scene::Pose& pose, const glm::dvec3& room) {
  return glm::dvec3(scene::model_matrix(pose) * glm::dvec4(room, 1.0));
}

void expect_near(const glm::dvec3& a, const glm::dvec3& b, double tolerance = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(Navigation, TheDeadZoneIsTakenOut) {
  EXPECT_EQ(beyond_dead_zone(0.05, 0.1), 0.0);
  EXPECT_EQ(beyond_dead_zone(-0.1, 0.1), 0.0);
  EXPECT_NEAR(beyond_dead_zone(0.55, 0.1), 0.5, 1e-12);
  EXPECT_NEAR(beyond_dead_zone(-1.0, 0.1), -1.0, 1e-12);
  EXPECT_EQ(beyond_dead_zone(3.0, 0.1), 1.0) << "beyond the travel: a full joystick";
  EXPECT_EQ(beyond_dead_zone(std::nan(""), 0.1), 0.0);
}

TEST(Navigation, ForwardGoesAlongTheWandAsTheWorldSeesIt) {
  const config::Navigation n = flystick_navigation();
  // The installation turned a quarter about y and at twice the scale: a metre
  // of the room along -z is two of the world's along -x.
  scene::Pose from;
  from.position = {5.0, 0.0, 0.0};
  from.rotation = glm::angleAxis(glm::radians(90.0), glm::dvec3(0, 1, 0));
  from.scale = glm::dvec3(2.0);
  const scene::Pose to = fly(from, n, 0.0, 1.0, glm::dvec3(0, 0, -1), {0, 1.6, 0}, 0.5);
  expect_near(to.position, {5.0 - 2.0 * 2.0 * 0.5, 0.0, 0.0});
  EXPECT_EQ(to.rotation, from.rotation);
  const scene::Pose blind = fly(from, n, 0.0, 1.0, std::nullopt, {0, 1.6, 0}, 0.5);
  EXPECT_EQ(blind.position, from.position) << "a wand the cameras do not see points nowhere";
}

TEST(Navigation, TurningKeepsTheEyesWhereTheyAre) {
  const config::Navigation n = flystick_navigation();
  scene::Pose from;
  from.position = {1.0, 0.0, 2.0};
  const glm::dvec3 eyes{0.5, 1.6, -0.3};
  const scene::Pose to = fly(from, n, 1.0, 0.0, std::nullopt, eyes, 1.0);  // a full second right: 90°
  expect_near(to_world(to, eyes), to_world(from, eyes));
  // Turned a quarter right: the room's ahead (-z) now looks along the world's
  // right (+x), and the room's right along the world's behind (+z).
  expect_near(glm::dvec3(scene::model_matrix(to) * glm::dvec4(0, 0, -1, 0)), {1, 0, 0});
  expect_near(glm::dvec3(scene::model_matrix(to) * glm::dvec4(1, 0, 0, 0)), {0, 0, 1});
}

TEST(Navigation, TheFlystickFliesAndItsButtonBringsItBack) {
  ViewerNavigation navigation(flystick_navigation(), config::Tracking{}, kPeriod);
  std::vector<session::Event> events;
  scene::SceneState state;
  navigation.input({stick(1, 0.0, 1.0)});
  navigation.step(0, state, 0, events);
  EXPECT_EQ(state.navigation.now.position, glm::dvec3(0.0));
  expect_near(state.navigation.next.position, {0, 0, -0.02});  // 2 m/s for a frame of 10 ms, along -z
  state = {};
  navigation.step(1, state, 0, events);
  expect_near(state.navigation.now.position, {0, 0, -0.02});  // where the last frame's next was
  expect_near(state.navigation.next.position, {0, 0, -0.04});

  navigation.input({stick(1, 0.0, 0.0, 3, true, 2)});
  state = {};
  navigation.step(2, state, 0, events);
  EXPECT_EQ(state.navigation.now.position, glm::dvec3(0.0)) << "the reset button: back home";
  navigation.input({stick(1, 0.0, 1.0, 3, true, 3)});
  state = {};
  navigation.step(3, state, 0, events);
  navigation.step(4, state, 0, events);
  EXPECT_LT(state.navigation.now.position.z, -0.01) << "held down, the button resets once";
}

TEST(Navigation, WhereAnApplicationSetsItTheFlightGoesOnAndTheButtonComesBack) {
  ViewerNavigation navigation(flystick_navigation(), config::Tracking{}, kPeriod);
  std::vector<session::Event> events;
  navigation.input({stick(1, 0.0, 1.0)});
  scene::SceneState state;
  navigation.step(0, state, 0, events);
  scene::Pose set;
  set.position = {100.0, 0.0, 0.0};
  state = {};
  state.navigation = {set, set};  // as put_live leaves it
  navigation.step(1, state, 1, events);
  EXPECT_EQ(state.navigation.now.position, set.position);
  expect_near(state.navigation.next.position, {100.0, 0.0, -0.02});
  state.navigation = {set, set};
  navigation.input({stick(1, 0.0, 0.0, 3, true, 2)});
  navigation.step(2, state, 1, events);
  EXPECT_EQ(state.navigation.now.position, set.position) << "home is where the application set it";
}

TEST(Navigation, WithoutANavigationWhatTheApplicationSetStays) {
  ViewerNavigation navigation(std::nullopt, config::Tracking{}, kPeriod);
  std::vector<session::Event> events;
  navigation.input({stick(1, 0.0, 1.0)});
  scene::SceneState state;
  scene::Pose set;
  set.position = {3.0, 0.0, 0.0};
  state.navigation = {set, set};
  navigation.step(0, state, 1, events);
  EXPECT_EQ(state.navigation.now, set);
  EXPECT_EQ(state.navigation.next, set);
}

TEST(Navigation, EachFlystickThatChangedIsAnEventOnceAFrame) {
  config::Tracking tracking;
  tracking.tracker_origin = {0.0, 1.0, 0.0};
  ViewerNavigation navigation(std::nullopt, tracking, kPeriod);
  std::vector<session::Event> events;
  tracking::FlystickSample a = stick(0, 0.5, 0.0, 2);
  a.position = {1000.0, 0.0, 0.0};  // millimetres
  navigation.input({a, stick(4, 0.0, 0.0)});
  a.arrival = 2;
  navigation.input({a});  // again, nothing changed but its arrival
  scene::SceneState state;
  navigation.step(7, state, 0, events);
  ASSERT_EQ(events.size(), 2u);
  const session::FlystickChanged& first = events[0].flystick();
  EXPECT_EQ(first.frame(), 7u);
  EXPECT_EQ(first.flystick(), 0u);
  EXPECT_TRUE(first.seen());
  ASSERT_EQ(first.position_size(), 3);
  EXPECT_DOUBLE_EQ(first.position(0), 1.0) << "in installation metres";
  EXPECT_DOUBLE_EQ(first.position(1), 1.0) << "the tracker's origin added";
  ASSERT_EQ(first.buttons_size(), 6);
  EXPECT_TRUE(first.buttons(2));
  EXPECT_FALSE(first.buttons(1));
  ASSERT_EQ(first.joystick_size(), 2);
  EXPECT_EQ(first.joystick(0), 0.5);

  events.clear();
  a.arrival = 3;
  navigation.input({a});
  navigation.step(8, state, 0, events);
  EXPECT_TRUE(events.empty()) << "nothing changed";
  a.buttons[2] = false;
  a.seen = false;
  navigation.input({a});
  navigation.step(9, state, 0, events);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_FALSE(events[0].flystick().seen());
  EXPECT_DOUBLE_EQ(events[0].flystick().position(0), 1.0) << "unseen: its last pose seen";
}

TEST(Navigation, TheFlysticksRememberedAreBounded) {
  ViewerNavigation navigation(std::nullopt, config::Tracking{}, kPeriod);
  std::vector<tracking::FlystickSample> many;
  for (std::uint32_t id = 0; id < 1000; ++id) many.push_back(stick(id, 0.0, 0.0));
  navigation.input(many);
  std::vector<session::Event> events;
  scene::SceneState state;
  navigation.step(0, state, 0, events);
  EXPECT_EQ(events.size(), kMostFlysticks);
}

}  // namespace
}  // namespace optique::master
