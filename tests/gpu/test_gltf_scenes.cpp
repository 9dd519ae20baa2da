// glTF files made by real exporters, drawn by real GL nodes (local clusters of
// optique-node-gl on llvmpipe, their captures read back): the textured torus in
// its four forms — obj2gltf's .gltf with its buffer and texture beside it, the
// same embedded, as a .glb, and gltf-pipeline's Draco-compressed .glb — gives
// the same capture, and the default lights show its texture near the brightness
// it has in an image viewer. Label `gpu`.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "image/compare.h"
#include "image/image_io.h"
#include "local_capture.h"
#include "process.h"

namespace optique::testing {
namespace {

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";
const std::string kTorus = kConfigs + "/assets/torus/";
constexpr std::uint64_t kFrame = 2;

// configs/gltf-torus.json showing `gltf` (absolute), written into `folder`.
std::string torus_config(const ScratchDir& folder, const std::string& gltf) {
  std::ifstream in(kConfigs + "/gltf-torus.json");
  nlohmann::json config = nlohmann::json::parse(in);
  config["scene"]["gltf"] = gltf;
  const std::string path = folder.file("torus.json");
  std::ofstream(path) << config.dump(1);
  return path;
}

image::FloatImage torus_capture(const std::string& form) {
  const ScratchDir folder("optique-gltf-scene");
  const CapturedRun out = run_and_capture(torus_config(folder, kTorus + form), static_cast<int>(kFrame) + 1, 1);
  return capture(out, "wall", kFrame);
}

void keep_on_failure(const std::string& what, const image::FloatImage& actual, const image::FloatImage& expected) {
  const ScratchDir dir_scratch("optique-gltf-failure");
  const std::string dir = dir_scratch.string();
  (void)image::write_exr(dir + "/actual.exr", actual);
  (void)image::write_exr(dir + "/expected.exr", expected);
  (void)image::write_exr(dir + "/difference-x10.exr", image::difference(actual, expected, 10.0f));
  ADD_FAILURE() << what << ": images in " << dir;
}

TEST(GltfScenes, TheFourFormsOfTheTorusRenderTheSameCapture) {
  const image::FloatImage separate = torus_capture("torus.gltf");
  ASSERT_EQ(separate.width, 640);
  double lit = 0.0;
  for (float v : separate.pixels) lit += v;
  EXPECT_GT(lit, 1000.0) << "the torus was not drawn";
  // Draco's quantization (gltf-pipeline's defaults: 11-bit positions, 10-bit
  // texture coordinates) moves the checker's sharp edges by up to a quarter of
  // a texel: measured 42.3 dB in the worst channel (58.9 dB over all channels
  // with 14-bit coordinates), so its bar is lower.
  const std::vector<std::pair<std::string, double>> forms{
      {"torus-embedded.gltf", 50.0}, {"torus.glb", 50.0}, {"torus-draco.glb", 40.0}};
  for (const auto& [form, bar] : forms) {
    const image::FloatImage other = torus_capture(form);
    auto comparison = image::compare(other, separate);
    ASSERT_TRUE(comparison.ok()) << comparison.error();
    const auto& c = comparison.value();
    const double worst = std::min({c.psnr_r, c.psnr_g, c.psnr_b});
    std::printf("%s against torus.gltf with its files beside it: PSNR R/G/B %.1f/%.1f/%.1f dB, max error %.4f\n",
                form.c_str(), c.psnr_r, c.psnr_g, c.psnr_b, c.max_abs_error);
    if (!(worst >= bar)) {
      keep_on_failure(form + ": worst channel " + std::to_string(worst) + " dB, under " + std::to_string(bar), other,
                      separate);
    }
  }
}

TEST(GltfScenes, TheDefaultLightsShowTheTexturesBrightness) {
  auto texture = image::read_image(kTorus + "torus.png");
  ASSERT_TRUE(texture.ok()) << texture.error();
  double texture_sum = 0.0;
  for (int y = 0; y < texture.value().height; ++y) {
    for (int x = 0; x < texture.value().width; ++x) {
      for (int c = 0; c < 3; ++c) texture_sum += texture.value().at(x, y, c);
    }
  }
  const double texture_mean = 255.0 * texture_sum / (3.0 * texture.value().width * texture.value().height);

  const image::FloatImage shown = torus_capture("torus.gltf");
  // The torus's pixels: anything but the black background.
  double sum = 0.0;
  int pixels = 0;
  for (int y = 0; y < shown.height; ++y) {
    for (int x = 0; x < shown.width; ++x) {
      const float r = shown.at(x, y, 0), g = shown.at(x, y, 1), b = shown.at(x, y, 2);
      if (std::max({r, g, b}) <= 0.0f) continue;
      sum += r + g + b;
      ++pixels;
    }
  }
  ASSERT_GT(pixels, 10000) << "the torus covers too little of the image";
  const double mean = 255.0 * sum / (3.0 * pixels);
  const double ratio = mean / texture_mean;
  std::printf("the torus's %d pixels: mean %.1f/255 against its texture's %.1f/255 (ratio %.2f)\n", pixels, mean,
              texture_mean, ratio);
  EXPECT_GT(ratio, 1.0 / 1.5);
  EXPECT_LT(ratio, 1.5);
}

}  // namespace
}  // namespace optique::testing
