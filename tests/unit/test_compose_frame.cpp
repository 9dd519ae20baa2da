#include "tools/compose.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/parse.h"
#include "image/convert.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "keystoned_wall.h"
#include "optics/blend.h"
#include "optics/compose.h"
#include "scratch.h"
#include "tools/screen_images.h"

namespace optique::tools {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kFrame = 7;

void add_homography(schema::Projector& p, const glm::dmat3& h) {
  for (double v : geometry::homography_rows(h)) p.add_homography(v);
}

// A 3 m × 1 m wall lit by two keystoned mono projectors (160 × 100 px), and a
// 2 m × 1 m floor lit by a stereo pair of aligned projectors (100 × 50 px).
config::LoadedConfig installation() {
  schema::Installation inst;
  auto add_screen = [&](const std::string& id, double width, double height, double ppm) {
    schema::Screen& s = *inst.add_screens();
    s.set_id(id);
    for (double v : {0.0, 0.0, 0.0}) s.add_origin(v);
    for (double v : {1.0, 0.0, 0.0}) s.add_right(v);
    for (double v : {0.0, 1.0, 0.0}) s.add_up(v);
    s.set_width(width);
    s.set_height(height);
    s.set_pixels_per_metre(ppm);
  };
  add_screen("wall", testing::kWallWidth, testing::kWallHeight, 100.0);
  add_screen("floor", 2.0, 1.0, 50.0);
  const auto quads = testing::keystoned_quads();
  for (int i = 0; i < 2; ++i) {
    schema::Projector& p = *inst.add_projectors();
    p.set_id("wall-" + std::to_string(i));
    p.set_width(160);
    p.set_height(100);
    p.set_screen("wall");
    add_homography(p, testing::homography_onto(quads[static_cast<std::size_t>(i)], 160, 100));
  }
  for (const char* eye : {"left", "right"}) {
    schema::Projector& p = *inst.add_projectors();
    p.set_id(std::string("floor-") + eye);
    p.set_width(100);
    p.set_height(50);
    p.set_screen("floor");
    p.set_eye(eye);
  }
  for (double v : {1.5, 0.5, 2.0}) inst.mutable_viewer()->add_eye(v);
  inst.mutable_scene()->set_builtin("cubes");
  auto parsed = config::parse_installation(inst, ".", "compose-test");
  EXPECT_TRUE(parsed.ok()) << parsed.error();
  config::LoadedConfig loaded;
  if (parsed.ok()) loaded.installation = std::move(parsed).value();
  return loaded;
}

// What the nodes would capture: `level` × the projector's blend weight.
void write_captures(const config::LoadedConfig& loaded, const std::string& captures) {
  const config::Installation& inst = loaded.installation;
  std::vector<geometry::ProjectorGeometry> wall;
  for (std::size_t i = 0; i < 2; ++i) wall.push_back(inst.projectors[i].geometry());
  for (std::size_t i = 0; i < inst.projectors.size(); ++i) {
    const config::Projector& p = inst.projectors[i];
    image::FloatImage weights;
    if (i < 2) {
      weights = optics::blend_weights(wall, i, inst.screens[0].area(), 0.0);
    } else {
      weights = image::FloatImage(p.width, p.height, 1);
      std::fill(weights.pixels.begin(), weights.pixels.end(), p.eye == config::Eye::left ? 0.25f : 0.75f);
    }
    image::FloatImage linear(weights.width, weights.height, 4);
    for (int y = 0; y < linear.height; ++y) {
      for (int x = 0; x < linear.width; ++x) {
        for (int k = 0; k < 3; ++k) linear.at(x, y, k) = weights.at(x, y, 0);
        linear.at(x, y, 3) = 1.0f;
      }
    }
    ASSERT_TRUE(image::write_frame(captures + "/" + p.id, kFrame, linear, image::encode_srgb(linear)).ok());
  }
}

struct Fixture {
  config::LoadedConfig config = installation();
  optique::testing::ScratchDir scratch{"optique-compose"};
  std::string dir = scratch.string();
  std::string captures = dir + "/nodes";
  std::string out = dir + "/out";
  std::ostringstream log_text;
  spdlog::logger log{"compose", std::make_shared<spdlog::sinks::ostream_sink_mt>(log_text)};

  Fixture() { write_captures(config, captures); }
  std::string capture(const std::string& projector) const {
    return image::frame_path(captures + "/" + projector, kFrame, "png");  // the signal, as the simulator reads it
  }
};

TEST(ComposeFrame, WritesOneCompositePerScreenAndEye) {
  Fixture f;
  auto composed = compose_frame(f.config, kFrame, f.captures, f.out, f.log);
  ASSERT_TRUE(composed.ok()) << composed.error();
  const ComposeSummary& summary = composed.value();
  EXPECT_EQ(summary.frame, kFrame);
  ASSERT_EQ(summary.screens.size(), 3u);
  EXPECT_EQ(summary.screens[0].folder, "wall");
  EXPECT_EQ(summary.screens[1].folder, "floor.left");
  EXPECT_EQ(summary.screens[2].folder, "floor.right");
  EXPECT_EQ(summary.screens[0].projectors, (std::vector<std::string>{"wall-0", "wall-1"}));
  EXPECT_EQ(summary.screens[2].projectors, (std::vector<std::string>{"floor-right"}));

  // Wall: the two projectors cover x < ~2.1 m; their weights add up to 1 there.
  const auto& wall = summary.screens[0];
  EXPECT_EQ(wall.width, 300);
  EXPECT_EQ(wall.height, 100);
  EXPECT_GT(wall.covered, 0.6);
  EXPECT_LT(wall.covered, 0.75);
  EXPECT_EQ(wall.exr_path, f.out + "/screens/wall/frame-000007.exr");
  EXPECT_TRUE(fs::is_regular_file(f.out + "/screens/wall/frame-000007.png"));
  auto exr = image::read_image(wall.exr_path);
  ASSERT_TRUE(exr.ok()) << exr.error();
  ASSERT_EQ(exr.value().width, 300);
  ASSERT_EQ(exr.value().height, 100);
  for (int u : {20, 60, 105, 110, 115, 150, 190}) EXPECT_NEAR(exr.value().at(u, 50, 0), 1.0, 2e-3) << "u " << u;
  EXPECT_EQ(exr.value().at(280, 50, 0), 0.0f);  // nobody lights the right end

  for (const auto& [folder, level] : {std::pair{"floor.left", 0.25}, std::pair{"floor.right", 0.75}}) {
    auto floor = image::read_image(image::frame_path(f.out + "/screens/" + folder, kFrame, "exr"));
    ASSERT_TRUE(floor.ok()) << floor.error();
    EXPECT_EQ(floor.value().width, 100);
    EXPECT_EQ(floor.value().height, 50);
    // The captures are 8-bit sRGB signals: one level near 0.75 is 3e-3 of light.
    EXPECT_NEAR(floor.value().at(50, 25, 1), level, 4e-3) << folder;
    auto png = image::read_image(image::frame_path(f.out + "/screens/" + folder, kFrame, "png"));
    ASSERT_TRUE(png.ok()) << png.error();
    EXPECT_NEAR(png.value().at(50, 25, 1), image::encode_srgb(floor.value()).at(50, 25, 1) / 255.0, 1e-6);
  }
  // One log line per composite, naming its file.
  EXPECT_NE(f.log_text.str().find("screens/floor.right/frame-000007.png"), std::string::npos) << f.log_text.str();
}

TEST(ComposeFrame, MissingCaptureIsNamedWithAHint) {
  Fixture f;
  fs::remove(f.capture("wall-1"));
  auto composed = compose_frame(f.config, kFrame, f.captures, f.out, f.log);
  ASSERT_FALSE(composed.ok());
  EXPECT_NE(composed.error().find(f.capture("wall-1")), std::string::npos) << composed.error();
  EXPECT_NE(composed.error().find("--capture-every"), std::string::npos) << composed.error();
  EXPECT_FALSE(fs::exists(f.out + "/screens")) << "nothing is written when a capture is missing";

  // A frame that was never captured names the first missing file and counts the rest.
  auto other = compose_frame(f.config, kFrame + 1, f.captures, f.out, f.log);
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().find("frame-000008.png"), std::string::npos) << other.error();
  EXPECT_NE(other.error().find("and 3 more"), std::string::npos) << other.error();
}

TEST(ComposeFrame, CaptureOfTheWrongSizeIsNamed) {
  Fixture f;
  image::ByteImage small(80, 50, 4);
  ASSERT_TRUE(image::write_png(f.capture("floor-left"), small).ok());
  auto composed = compose_frame(f.config, kFrame, f.captures, f.out, f.log);
  ASSERT_FALSE(composed.ok());
  EXPECT_NE(composed.error().find(f.capture("floor-left")), std::string::npos) << composed.error();
  EXPECT_NE(composed.error().find("80×50"), std::string::npos) << composed.error();
  EXPECT_NE(composed.error().find("100×50"), std::string::npos) << composed.error();
}

TEST(ComposeFrame, UnreadableCaptureIsNamed) {
  Fixture f;
  std::ofstream(f.capture("wall-0"), std::ios::trunc) << "not a PNG";
  auto composed = compose_frame(f.config, kFrame, f.captures, f.out, f.log);
  ASSERT_FALSE(composed.ok());
  EXPECT_NE(composed.error().find(f.capture("wall-0")), std::string::npos) << composed.error();
  EXPECT_NE(composed.error().find("wall-0"), std::string::npos) << composed.error();
}

TEST(CompositeFolder, NamesEyes) {
  EXPECT_EQ(screen_image_folder("front", config::Eye::mono), "front");
  EXPECT_EQ(screen_image_folder("front", config::Eye::left), "front.left");
  EXPECT_EQ(screen_image_folder("front", config::Eye::right), "front.right");
}

}  // namespace
}  // namespace optique::tools
