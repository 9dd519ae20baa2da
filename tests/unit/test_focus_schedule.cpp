// The focal depth of each frame (master/focus_schedule.h): fixed, scripted, or
// ray cast under the gaze point.

#include "master/focus_schedule.h"

#include <gtest/gtest.h>

#include "config/load.h"
#include "master/run/scene_authority.h"
#include "scene/builtin.h"

namespace optique::master {
namespace {

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

config::Installation load(const std::string& name) {
  auto loaded = config::load_installation(kConfigs + "/" + name);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  return loaded ? loaded.value().installation : config::Installation{};
}

TEST(FocusSchedule, NoDepthOfFieldNoSchedule) { EXPECT_FALSE(FocusSchedule::make(load("single-wall.json"))); }

TEST(FocusSchedule, ScriptedDepthSweepsNearToFarAndBack) {
  const config::Installation installation = load("dof-pair.json");
  const auto schedule = FocusSchedule::make(installation);
  ASSERT_TRUE(schedule);
  const scene::SceneDefinition scene = scene::builtin_scene("depth-stack").value();
  const scene::SceneState state;
  const glm::dvec3 eye(0.0, 1.2, 2.0);
  EXPECT_NEAR(schedule->at(0.0, scene, state, eye).depth, 1.5, 1e-12);
  EXPECT_NEAR(schedule->at(1.25, scene, state, eye).depth, 4.75, 1e-12);
  EXPECT_NEAR(schedule->at(2.5, scene, state, eye).depth, 8.0, 1e-12);
  EXPECT_NEAR(schedule->at(5.0 + 1.25, scene, state, eye).depth, 4.75, 1e-12);  // looped
}

TEST(FocusSchedule, GazeFocusesOnWhatIsUnderIt) {
  const config::Installation installation = load("dof-inset.json");
  const auto schedule = FocusSchedule::make(installation);
  ASSERT_TRUE(schedule);
  const scene::SceneDefinition scene = scene::builtin_scene("depth-stack").value();
  const SceneAuthority authority(scene.objects, installation.viewer, 60.0);
  const scene::SceneState state = authority.state_at_frame(0);
  // The gaze starts at screen [0.27, 0.9] m = world (−1.33, 1.2, 0): the eye
  // at (0, 1.2, 2) sees the nearest slab there (centre (−1, 1.2, 0.5), 3 cm
  // thick: front face at z 0.515), 1.485 m away along the screen's normal.
  const protocol::Focus at_start = schedule->at(0.0, scene, state, state.eye_now);
  EXPECT_NEAR(at_start.gaze.x, 0.27, 1e-12);
  EXPECT_NEAR(at_start.gaze.y, 0.9, 1e-12);
  EXPECT_NEAR(at_start.depth, 2.0 - 0.515, 1e-9);
  // At 0.8 m/s the gaze reaches x = 1.6 m (world x 0) after 1.6625 s: the
  // middle slab, centre z = −1.5, front face at −1.485.
  const protocol::Focus later = schedule->at(1.6625, scene, state, state.eye_now);
  EXPECT_NEAR(later.gaze.x, 1.6, 1e-12);
  EXPECT_NEAR(later.depth, 2.0 + 1.485, 1e-9);
  // Between slabs the ray meets nothing: the far end of the depth of field.
  EXPECT_NEAR(schedule->at(0.5, scene, state, state.eye_now).depth, 10.0, 1e-12);
}

}  // namespace
}  // namespace optique::master
