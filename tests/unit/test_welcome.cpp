// A node's job as the welcome carries it (common/protocol/welcome.h): what the
// master encodes decodes to the job config::job_for cuts out, and a welcome
// that would not pass as a config is refused, naming what is wrong.

#include "protocol/welcome.h"

#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <filesystem>
#include <limits>

#include "config/load.h"
#include "config/to_schema.h"
#include "protocol/focus.h"
#include "scene/state.h"

namespace optique::protocol {
namespace {

namespace fs = std::filesystem;

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

config::Installation load(const std::string& name) {
  auto loaded = config::load_installation(kConfigs + "/" + name);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  return loaded ? loaded.value().installation : config::Installation{};
}

// Comparable: the job written back as its schema.
std::string bytes_of(const config::ProjectorJob& job) {
  return config::to_schema(job.installation).SerializeAsString() + "/" + std::to_string(job.projector);
}

TEST(Welcome, EveryShippedProjectorsJobArrivesAsItWasCut) {
  const scene::SceneManifest files{
      4096,
      {scene::describe_file("s.gltf", "{}", 4096), scene::describe_file("maps/a.png", std::string(9000, 'x'), 4096)}};
  std::size_t checked = 0;
  for (const auto& entry : fs::directory_iterator(kConfigs)) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().filename().string());
    const config::Installation installation = load(entry.path().filename().string());
    for (std::size_t i = 0; i < installation.projectors.size(); ++i) {
      const config::Projector& p = installation.projectors[i];
      const LightShare share{{0, 2}, true};
      const bool lights = p.content.role == config::ContentRole::lights;
      const wire::Welcome welcome = encode_welcome(installation, i, files, 20, 16'666'666, lights ? &share : nullptr);
      auto decoded = decode_welcome(welcome, p.id);
      ASSERT_TRUE(decoded.ok()) << p.id << ": " << decoded.error();
      const NodeJob& job = decoded.value();
      EXPECT_EQ(bytes_of(job.job), bytes_of(config::job_for(installation, i))) << p.id;
      EXPECT_EQ(job.job.self().id, p.id);
      EXPECT_EQ(job.scene_sha256, scene::manifest_sha256(files));
      EXPECT_EQ(job.scene_files.files.size(), 2u);
      EXPECT_EQ(job.scene_files.files[1].chunk_sha256, files.files[1].chunk_sha256);
      EXPECT_EQ(job.light_count, 20u);
      EXPECT_EQ(job.frame_period, 16'666'666);
      EXPECT_EQ(job.heartbeat, installation.master.heartbeat);
      EXPECT_EQ(job.liveness_timeout, installation.master.liveness_timeout);
      EXPECT_EQ(job.lights.has_value(), lights);
      if (lights) {
        EXPECT_EQ(*job.lights, share);
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 20u);
}

// A placed model is placed on the node too: the placement travels in the job.
TEST(Welcome, AModelsPlacementArrivesWithTheJob) {
  config::Installation installation = load("gltf-torus.json");
  scene::Placement placement;
  placement.rotation = glm::angleAxis(0.5, glm::dvec3(0.0, 1.0, 0.0));
  placement.fit = scene::Placement::Fit{{0.0, 0.2, -0.4}, {1.5, 0.8, 0.5}};
  installation.scene.placement = placement;
  auto decoded = decode_welcome(encode_welcome(installation, 0, {}, 0, 16'666'666, nullptr),
                                installation.projectors[0].id);
  ASSERT_TRUE(decoded.ok()) << decoded.error();
  ASSERT_TRUE(decoded.value().job.installation.scene.placement.has_value());
  const scene::Placement& arrived = *decoded.value().job.installation.scene.placement;
  EXPECT_EQ(arrived.fit->centre, placement.fit->centre);
  EXPECT_EQ(arrived.fit->size, placement.fit->size);
  EXPECT_NEAR(glm::length(glm::dvec4(arrived.rotation.w, arrived.rotation.x, arrived.rotation.y, arrived.rotation.z) -
                          glm::dvec4(placement.rotation.w, placement.rotation.x, placement.rotation.y,
                                     placement.rotation.z)),
              0.0, 1e-15);
}

// A welcome for the first projector of the 2×2 wall, for the tests below to spoil.
wire::Welcome good_welcome() { return encode_welcome(load("powerwall-2x2.json"), 0, {}, 0, 16'666'666, nullptr); }

std::string error_of(const wire::Welcome& welcome, const std::string& id = "bottom-left") {
  auto decoded = decode_welcome(welcome, id);
  return decoded ? std::string("(accepted)") : decoded.error();
}

TEST(Welcome, RefusesAJobForAnotherProjector) {
  EXPECT_NE(error_of(good_welcome(), "bottom-right").find("it is for projector 'bottom-left'"), std::string::npos)
      << error_of(good_welcome(), "bottom-right");
}

TEST(Welcome, RefusesTimingsOutOfRange) {
  for (const std::int64_t period : {std::int64_t{0}, std::int64_t{-5}, std::int64_t{11'000'000'000}}) {
    wire::Welcome w = good_welcome();
    w.set_frame_period_ns(period);
    EXPECT_NE(error_of(w).find("frame_period_ns"), std::string::npos) << period;
  }
  wire::Welcome w = good_welcome();
  w.set_heartbeat_ms(0);
  EXPECT_NE(error_of(w).find("heartbeat_ms 0"), std::string::npos) << error_of(w);
}

TEST(Welcome, RefusesAProjectorThatWouldNotPassAsAConfig) {
  wire::Welcome w = good_welcome();
  w.mutable_projector()->set_width(0);
  for (auto& member : *w.mutable_blend_group()) {
    if (member.id() == "bottom-left") member.set_width(0);
  }
  EXPECT_NE(error_of(w).find("welcome: projectors[0].width: must be 1..16384 pixels (got 0)"), std::string::npos)
      << error_of(w);

  wire::Welcome nan = good_welcome();
  for (auto& member : *nan.mutable_blend_group()) {
    member.clear_region();
    for (int k = 0; k < 9; ++k) member.add_homography(k == 4 ? std::numeric_limits<double>::quiet_NaN() : 1.0);
  }
  EXPECT_NE(error_of(nan).find("homography[4]: must be a finite number"), std::string::npos) << error_of(nan);

  wire::Welcome screen = good_welcome();
  screen.mutable_screen()->set_height(-1.0);
  EXPECT_NE(error_of(screen).find("screens[0].height: must be > 0"), std::string::npos) << error_of(screen);
}

TEST(Welcome, RefusesAShareOfLightsTheSceneDoesNotHave) {
  config::Installation installation = load("stacked-lighting-3.json");
  const LightShare beyond{{3, 20 + scene::kMaxAddedLights}, false};  // 20 of its own, and 64 that may be added
  auto decoded = decode_welcome(encode_welcome(installation, 0, {}, 20, 16'666'666, &beyond), "lights-a");
  ASSERT_FALSE(decoded.ok());
  EXPECT_NE(
      decoded.error().find("welcome: lights: light 84 does not exist (the scene has 20, and at most 64 may be added)"),
      std::string::npos)
      << decoded.error();
  const LightShare twice{{4, 4}, false};
  auto repeated = decode_welcome(encode_welcome(installation, 0, {}, 20, 16'666'666, &twice), "lights-a");
  ASSERT_FALSE(repeated.ok());
  EXPECT_NE(repeated.error().find("lights must ascend, each once"), std::string::npos) << repeated.error();
}

TEST(Focus, DecodesFiniteDepthsAndRefusesTheRest) {
  auto good = decode_focus(to_wire(Focus{2.5, {0.3, 0.4}}));
  ASSERT_TRUE(good.ok()) << good.error();
  EXPECT_EQ(good.value(), (Focus{2.5, {0.3, 0.4}}));
  for (const double depth : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::nan("")}) {
    EXPECT_FALSE(decode_focus(to_wire(Focus{depth, {0.0, 0.0}})).ok()) << depth;
  }
  EXPECT_FALSE(decode_focus(to_wire(Focus{1.0, {std::nan(""), 0.0}})).ok());
}

}  // namespace
}  // namespace optique::protocol
