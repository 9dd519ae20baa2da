// A tracked head turns the stereo axis: the eyes sit along the head's own
// right, however it is turned. On the CAVE's front wall in stereo, a head facing
// it upright sees the two images apart sideways; the same head tilted onto its
// shoulder (rolled a quarter turn about the line of sight) sees them apart up
// and down.

#include <gtest/gtest.h>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "config/job.h"
#include "gl_installation.h"
#include "image/image.h"
#include "master/run/scene_authority.h"
#include "render/projector_pipeline.h"

namespace optique {
namespace {

// The brightness-weighted mean column and row: how far they move between the
// two eyes' images is the parallax, sideways and up and down.
glm::dvec2 mean_place(const image::FloatImage& image) {
  double sum = 0.0;
  glm::dvec2 weighted{0.0};
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const double v = image.at(x, y, 0) + image.at(x, y, 1) + image.at(x, y, 2);
      sum += v;
      weighted += v * glm::dvec2(x, y);
    }
  }
  return weighted / sum;
}

TEST(TrackedEyes, TheStereoAxisTurnsWithTheHead) {
  auto opened = testing::open_gl_installation(OPTIQUE_SOURCE_DIR "/configs/cave-tracked.json");
  ASSERT_TRUE(opened) << opened.error();
  testing::GlInstallation gl = std::move(opened).value();
  const config::Installation& installation = gl.config.installation;
  ASSERT_EQ(installation.projectors[0].eye, config::Eye::left);
  ASSERT_EQ(installation.projectors[1].eye, config::Eye::right);
  auto left = render::ProjectorPipeline::make(config::job_for(installation, 0), gl.scene);
  auto right = render::ProjectorPipeline::make(config::job_for(installation, 1), gl.scene);
  ASSERT_TRUE(left && right);
  const master::SceneAuthority authority(gl.scene.objects, installation.viewer, installation.master.frame_rate);
  scene::SceneState facing = authority.state_at_frame(30);
  facing.eye_now = facing.eye_next = {0.0, 1.6, 0.0};
  scene::SceneState rolled = facing;
  // A quarter turn about the line of sight (the front wall is at −z): the head's
  // right now points up.
  rolled.head_now = rolled.head_next = glm::angleAxis(glm::radians(90.0), glm::dvec3(0.0, 0.0, 1.0));

  const double separation = installation.viewer.eye_separation;
  const glm::dvec3 apart_facing = right.value()->eye(facing, 0.0) - left.value()->eye(facing, 0.0);
  const glm::dvec3 apart_rolled = right.value()->eye(rolled, 0.0) - left.value()->eye(rolled, 0.0);
  EXPECT_LT(glm::distance(apart_facing, glm::dvec3(separation, 0.0, 0.0)), 1e-12);
  EXPECT_LT(glm::distance(apart_rolled, glm::dvec3(0.0, separation, 0.0)), 1e-12);

  const auto parallax = [](render::ProjectorPipeline& l, render::ProjectorPipeline& r, const scene::SceneState& state) {
    EXPECT_TRUE(l.draw_frame(state));
    const glm::dvec2 from_left = mean_place(l.renderer().output().read_linear());
    EXPECT_TRUE(r.draw_frame(state));
    return mean_place(r.renderer().output().read_linear()) - from_left;
  };
  const glm::dvec2 upright = parallax(*left.value(), *right.value(), facing);
  const glm::dvec2 tilted = parallax(*left.value(), *right.value(), rolled);
  std::cout << "front wall, the right image's mean place less the left's (columns, rows): upright (" << upright.x
            << ", " << upright.y << ") px, tilted (" << tilted.x << ", " << tilted.y << ") px\n";
  // Measured (10.0, −1.0) and (2.8, 11.5): what enters and leaves the image's
  // edges moves the mean across the parallax too.
  EXPECT_GT(std::abs(upright.x), 2.0) << "the cubes stand off the wall: the eyes see them apart";
  EXPECT_GT(std::abs(upright.x), 4.0 * std::abs(upright.y)) << "upright: apart sideways";
  EXPECT_GT(std::abs(tilted.y), 2.0 * std::abs(tilted.x)) << "tilted: apart up and down";
  EXPECT_GT(std::abs(tilted.y), 0.5 * std::abs(upright.x)) << "and about as far";
}

}  // namespace
}  // namespace optique
