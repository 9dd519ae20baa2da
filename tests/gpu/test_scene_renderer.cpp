// SceneRenderer in this process (headless GL): base colour textures are sampled
// with sRGB decoding, and glTF texture coordinates land the right way up: a quad
// filling the view with uv (0, 0) at its top-left corner shows the image's
// top-left texel top left.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "geometry/projection.h"
#include "image/texture_decode.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/gltf.h"
#include "scene/state.h"

namespace optique::render {
namespace {

// Odd multiples of 2 put a pixel centre exactly on each texel centre of a 2×2
// texture (uv 0.25 and 0.75): pixels 16 and 49 of 66.
constexpr int kSize = 66;
constexpr int kNear = 16;
constexpr int kFar = 49;
constexpr float kTolerance = 2e-3f;
const glm::dvec3 kEye{0.0, 0.0, 2.0};

// The 2×2 image, top row first: RGB (sRGB-encoded) and alpha 255.
const std::vector<std::uint8_t> kChecker{255, 128, 64,  255, 0,   255, 128, 255,   // top-left, top-right
                                         64,  0,   255, 255, 128, 64,  0,   255};  // bottom-left, bottom-right

float srgb_to_linear(std::uint8_t encoded) {
  const double c = encoded / 255.0;
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

// The viewer 2 m in front of a 2 m × 2 m screen in the z = 0 plane.
geometry::Frustum view_of_unit_square() {
  geometry::WorldRect rect;
  rect.lower_left = {-1.0, -1.0, 0.0};
  rect.width = 2.0;
  rect.height = 2.0;
  auto frustum = geometry::off_axis_frustum(rect, kEye, 0.1, 10.0);
  EXPECT_TRUE(frustum.ok());
  return frustum.ok() ? frustum.value() : geometry::Frustum{};
}

// The quad that exactly fills that screen, uv (0, 0) top left, facing the viewer.
scene::Mesh textured_quad() {
  scene::Mesh mesh;
  mesh.name = "quad";
  const glm::vec3 normal(0.0f, 0.0f, 1.0f);
  mesh.vertices = {{{-1.0f, 1.0f, 0.0f}, normal, {0.0f, 0.0f}},
                   {{1.0f, 1.0f, 0.0f}, normal, {1.0f, 0.0f}},
                   {{1.0f, -1.0f, 0.0f}, normal, {1.0f, 1.0f}},
                   {{-1.0f, -1.0f, 0.0f}, normal, {0.0f, 1.0f}}};
  mesh.indices = {0, 3, 2, 0, 2, 1};
  return mesh;
}

class SceneRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto context = make_headless_context();
    // GL tests run headless everywhere (llvmpipe without a GPU): no context is a failure.
    ASSERT_TRUE(context.ok()) << "no headless OpenGL context: " << context.error();
    context_ = std::move(context).value();
  }

  // Lit by ambient (1, 1, 1) only: what it draws is the base colour.
  static void only_ambient(scene::SceneDefinition& scene) {
    scene.lights.clear();
    scene.ambient = glm::vec3(1.0f);
    scene.background = glm::vec3(0.0f);
    for (auto& material : scene.materials) material.emissive = glm::vec3(0.0f);
  }

  // Renders `scene` and checks each quadrant's centre against the texel that
  // should appear there.
  void expect_checker(const scene::SceneDefinition& scene) {
    auto renderer = SceneRenderer::create(scene, kSize, kSize);
    ASSERT_TRUE(renderer.ok()) << renderer.error();
    renderer.value()->draw(scene::SceneState{}, 0.0, kEye, view_of_unit_square());
    const image::FloatImage image = renderer.value()->read_linear();  // top row first
    ASSERT_EQ(image.width, kSize);
    ASSERT_EQ(image.height, kSize);
    struct Quadrant {
      const char* name;
      int x, y;
      std::size_t texel;
    };
    for (const Quadrant& q : {Quadrant{"top-left", kNear, kNear, 0}, Quadrant{"top-right", kFar, kNear, 1},
                              Quadrant{"bottom-left", kNear, kFar, 2}, Quadrant{"bottom-right", kFar, kFar, 3}}) {
      for (int c = 0; c < 3; ++c) {
        const float expected = srgb_to_linear(kChecker[4 * q.texel + static_cast<std::size_t>(c)]);
        EXPECT_NEAR(image.at(q.x, q.y, c), expected, kTolerance) << q.name << " channel " << c;
      }
    }
  }

  std::unique_ptr<GlContext> context_;
};

TEST(SrgbDecoding, ReferenceValues) {
  EXPECT_NEAR(srgb_to_linear(0), 0.0f, 1e-7f);
  EXPECT_NEAR(srgb_to_linear(64), 0.0512695f, 1e-6f);
  EXPECT_NEAR(srgb_to_linear(128), 0.2158605f, 1e-6f);
  EXPECT_NEAR(srgb_to_linear(255), 1.0f, 1e-7f);
}

TEST_F(SceneRendererTest, TextureIsDecodedFromSrgbAndTheRightWayUp) {
  scene::SceneDefinition scene;
  scene.name = "textured quad";
  scene.meshes.push_back(textured_quad());
  scene.textures.push_back({"checker", 2, 2, kChecker});
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 0u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  only_ambient(scene);
  expect_checker(scene);
}

TEST_F(SceneRendererTest, BaseColourFactorMultipliesTheTexture) {
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());
  scene.textures.push_back({"white", 1, 1, {255, 255, 255, 255}});
  scene.materials.emplace_back(glm::vec3(0.5f, 0.25f, 1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 0u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  only_ambient(scene);
  auto renderer = SceneRenderer::create(scene, kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  renderer.value()->draw(scene::SceneState{}, 0.0, kEye, view_of_unit_square());
  const auto image = renderer.value()->read_rendered();
  EXPECT_NEAR(image.at(kSize / 2, kSize / 2, 0), 0.5f, kTolerance);
  EXPECT_NEAR(image.at(kSize / 2, kSize / 2, 1), 0.25f, kTolerance);
  EXPECT_NEAR(image.at(kSize / 2, kSize / 2, 2), 1.0f, kTolerance);
}

TEST_F(SceneRendererTest, TexturedQuadFromGltf) {
  auto loaded = scene::load_gltf(OPTIQUE_SOURCE_DIR "/tests/data/gltf/textured-quad.gltf", image::decode_texture);
  ASSERT_TRUE(loaded.ok()) << loaded.error();
  scene::SceneDefinition scene = std::move(loaded).value().scene;
  ASSERT_EQ(scene.textures.size(), 1u);
  only_ambient(scene);
  expect_checker(scene);
}

TEST_F(SceneRendererTest, MaterialTextureOutOfRangeFailsCreate) {
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 3u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  EXPECT_FALSE(SceneRenderer::create(scene, kSize, kSize).ok());
}

}  // namespace
}  // namespace optique::render
