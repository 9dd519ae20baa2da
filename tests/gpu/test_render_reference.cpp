// render-reference with a supersample factor: the same raster, each pixel the
// average of S × S samples. Needs GL (headless; llvmpipe in CI): label `gpu`.

#include "scene_load/installation_scene.h"
#include "image/texture_decode.h"
#include "tools/render_reference.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>
#include <stdlib.h>

#include <filesystem>
#include <map>

#include "image/compare.h"
#include "image/convert.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "optics/compose.h"
#include "scratch.h"

namespace optique::tools {
namespace {

namespace fs = std::filesystem;

struct Rendered {
  image::FloatImage linear;
  image::FloatImage encoded;
};

// render-reference of `frame` into a temporary folder; the folders it wrote
// under reference/ and, for each, its EXR and PNG read back.
struct References {
  std::map<std::string, Rendered> images;  // by folder: "front", "front.left", …
};

References render_references(const config::LoadedConfig& config, const scene::LoadedScene& scene, std::uint64_t frame,
                             int supersample) {
  References out;
  const optique::testing::ScratchDir scratch("optique-reference");
  const std::string dir = scratch.string();
  spdlog::logger log("reference", std::make_shared<spdlog::sinks::null_sink_mt>());
  ReferenceOptions options;
  options.supersample = supersample;
  const auto written = render_reference(config, scene, frame, dir, log, options);
  EXPECT_TRUE(written.ok()) << written.error();
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir + "/reference", ec)) {
    const std::string folder = entry.path().string();
    auto linear = image::read_image(image::frame_path(folder, frame, "exr"));
    auto encoded = image::read_image(image::frame_path(folder, frame, "png"));
    EXPECT_TRUE(linear.ok() && encoded.ok()) << folder;
    if (linear.ok() && encoded.ok()) {
      out.images[entry.path().filename().string()] = {std::move(linear).value(), std::move(encoded).value()};
    }
  }
  return out;
}

Rendered render(int supersample) {
  auto config = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/single-wall.json");
  EXPECT_TRUE(config.ok()) << config.error();
  auto scene = config::load_scene(config.value().installation, image::decode_texture);
  EXPECT_TRUE(scene.ok()) << scene.error();
  if (!config.ok() || !scene.ok()) return {};
  return render_references(config.value(), scene.value(), 30, supersample).images["front"];
}

TEST(RenderReference, SupersampledHasTheScreensPixelsAndAveragesThem) {
  const Rendered one = render(1);
  const Rendered four = render(4);
  ASSERT_FALSE(one.linear.empty());
  ASSERT_FALSE(four.linear.empty());
  // single-wall: 4 m × 2.25 m at 160 px/m.
  EXPECT_EQ(four.linear.width, 640);
  EXPECT_EQ(four.linear.height, 360);
  EXPECT_EQ(one.linear.width, 640);
  // Same picture, edges antialiased: close but not identical.
  auto comparison = image::compare(one.linear, four.linear);
  ASSERT_TRUE(comparison.ok()) << comparison.error();
  std::printf("1×1 vs 4×4 samples: PSNR luma %.1f dB, max |Δ| %.3f\n", comparison.value().psnr_luma,
              comparison.value().max_abs_error);
  EXPECT_GT(comparison.value().psnr_luma, 25.0);
  EXPECT_GT(comparison.value().max_abs_error, 0.05);
  // The PNG is the sRGB encoding of the averaged linear image (to the EXR's
  // half-float rounding).
  const image::ByteImage expected = image::encode_srgb(four.linear);
  int off = 0;
  for (int y = 0; y < four.encoded.height; ++y) {
    for (int x = 0; x < four.encoded.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        off += std::abs(four.encoded.at(x, y, c) * 255.0f - expected.at(x, y, c)) > 1.01f ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(off, 0);
}

TEST(RenderReference, RefusesAZeroFactor) {
  auto config = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/single-wall.json");
  ASSERT_TRUE(config.ok()) << config.error();
  auto scene = config::load_scene(config.value().installation, image::decode_texture);
  ASSERT_TRUE(scene.ok()) << scene.error();
  spdlog::logger log("reference", std::make_shared<spdlog::sinks::null_sink_mt>());
  auto written = render_reference(config.value(), scene.value(), 0, "/nonexistent", log, ReferenceOptions{0});
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().find("supersample"), std::string::npos) << written.error();
}

// compose writes a stereo screen's composites as <screen>.left and .right: the
// reference has one for each eye too, each seen from its eye.
TEST(RenderReference, AStereoScreenHasAReferenceForEachEye) {
  auto config = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/single-wall.json");
  ASSERT_TRUE(config.ok()) << config.error();
  config::Installation& installation = config.value().installation;
  ASSERT_FALSE(installation.projectors.empty());
  config::Projector right = installation.projectors.front();
  right.id += "-right";
  right.eye = config::Eye::right;
  installation.projectors.front().eye = config::Eye::left;
  installation.projectors.push_back(right);
  auto scene = config::load_scene(installation, image::decode_texture);
  ASSERT_TRUE(scene.ok()) << scene.error();
  References refs = render_references(config.value(), scene.value(), 30, 1);
  ASSERT_EQ(refs.images.count("front.left"), 1u);
  ASSERT_EQ(refs.images.count("front.right"), 1u);
  EXPECT_EQ(refs.images.count("front"), 0u) << "no mono reference for a screen seen only in stereo";
  auto comparison = image::compare(refs.images["front.left"].linear, refs.images["front.right"].linear);
  ASSERT_TRUE(comparison.ok()) << comparison.error();
  EXPECT_GT(comparison.value().max_abs_error, 0.05) << "the two eyes see the cubes from 6.5 cm apart";
}

// An analytic edge: a white emissive quad in the screen plane whose left edge
// lies 0.3 px into pixel column 100 (wherever the viewer is, what lies in the
// screen plane lands where it is). A box filter over 4 × 4 samples at offsets
// 1/8, 3/8, 5/8, 7/8 sees it in 3 of 4 columns of samples: 0.75; one sample
// per pixel (at 1/2) sees all of it: 1. The PNG holds 0.75 sRGB-encoded: 225.
TEST(RenderReference, SupersamplingAveragesTheSamplesOfAPixel) {
  auto config = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/single-wall.json");
  ASSERT_TRUE(config.ok()) << config.error();
  const config::Screen& screen = config.value().installation.screens.front();
  ASSERT_EQ(screen.pixels_per_metre, 160.0);
  const double x0 = (100.0 + 0.3) / screen.pixels_per_metre;  // metres from the screen's left edge
  const auto at = [&](double u, double v) { return glm::vec3(screen.origin + screen.right * u + screen.up * v); };
  scene::LoadedScene edge;
  scene::Mesh quad;
  quad.name = "edge";
  const glm::vec3 normal(glm::cross(screen.right, screen.up));
  quad.vertices = {{at(x0, 0.0), normal, {}},
                   {at(screen.width + 1.0, 0.0), normal, {}},
                   {at(screen.width + 1.0, screen.height + 1.0), normal, {}},
                   {at(x0, screen.height + 1.0), normal, {}}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  edge.definition.name = "analytic edge";
  edge.definition.meshes.push_back(quad);
  edge.definition.materials.emplace_back(glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(1.0f));
  edge.definition.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  edge.definition.ambient = glm::vec3(0.0f);

  References four = render_references(config.value(), edge, 0, 4);
  References one = render_references(config.value(), edge, 0, 1);
  ASSERT_EQ(four.images.count("front"), 1u);
  ASSERT_EQ(one.images.count("front"), 1u);
  const image::FloatImage& four_linear = four.images["front"].linear;
  const image::FloatImage& four_encoded = four.images["front"].encoded;
  const image::FloatImage& one_linear = one.images["front"].linear;
  ASSERT_EQ(four_linear.width, 640);
  for (const int y : {10, 180, 350}) {
    EXPECT_NEAR(four_linear.at(99, y, 0), 0.0f, 1e-6f) << "row " << y;
    EXPECT_NEAR(four_linear.at(100, y, 0), 0.75f, 1e-3f) << "row " << y << ": 12 of 16 samples";
    EXPECT_NEAR(four_linear.at(101, y, 0), 1.0f, 1e-3f) << "row " << y;
    EXPECT_NEAR(four_encoded.at(100, y, 0) * 255.0f, 225.0f, 0.01f) << "row " << y << ": 0.75 in sRGB";
    EXPECT_NEAR(one_linear.at(100, y, 0), 1.0f, 1e-3f) << "row " << y << ": the one sample at the centre is inside";
  }
}

}  // namespace
}  // namespace optique::tools
