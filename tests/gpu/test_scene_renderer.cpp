// SceneRenderer in this process (headless GL): base colour textures are sampled
// with sRGB decoding, and glTF texture coordinates land the right way up: a quad
// filling the view with uv (0, 0) at its top-left corner shows the image's
// top-left texel top left.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "geometry/projection.h"
#include "image/convert.h"
#include "image/texture_decode.h"
#include "optics/projector_model.h"
#include "render/box_reduce.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "scene_load/gltf.h"

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

// The sRGB curve as optique's projector model has it (its known values are
// checked in tests/unit/test_projector_model.cpp); here GL's texture decoding
// must agree with it.
float srgb_to_linear(std::uint8_t encoded) {
  return static_cast<float>(optics::ProjectorModel().response(encoded / 255.0));
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
    renderer.value()->draw(scene::SceneState{}, {0.0, kEye, view_of_unit_square()});
    const image::FloatImage image = renderer.value()->output().read_linear();  // top row first
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
  renderer.value()->draw(scene::SceneState{}, {0.0, kEye, view_of_unit_square()});
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

// The output pass (GLSL) sends the signal the projector model (C++) says makes
// the projector add the rendered light: for every pixel of a ramp through all
// 256 texture codes, with each kind of response curve. The known values of the
// curves are the unit test's; this holds the shader to them.
TEST_F(SceneRendererTest, OutputPassSendsTheSignalTheProjectorModelGives) {
  constexpr int kWidth = 256;
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());
  scene::Texture ramp{"ramp", kWidth, 1, {}};
  for (int code = 0; code < kWidth; ++code) {
    const auto c = static_cast<std::uint8_t>(code);
    const auto d = static_cast<std::uint8_t>(255 - code);
    ramp.rgba.insert(ramp.rgba.end(), {c, d, static_cast<std::uint8_t>((code * 7) % 256), 255});
  }
  scene.textures.push_back(ramp);
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 0u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  only_ambient(scene);

  struct Case {
    const char* name;
    config::ProjectorResponse response;
  };
  std::vector<Case> cases;
  cases.push_back({"sRGB, 8 bits", {}});
  config::ProjectorResponse gamma;
  gamma.curve = config::ResponseCurve::gamma;
  gamma.gamma = 2.2;
  gamma.bits = 10;
  gamma.black_level = 0.05;
  gamma.brightness = 0.8;
  cases.push_back({"gamma 2.2, 10 bits, black 0.05, brightness 0.8", gamma});
  config::ProjectorResponse table;
  table.curve = config::ResponseCurve::table;
  table.table = {0.0, 0.02, 0.2, 0.2, 0.6, 1.0};
  table.bits = 12;
  cases.push_back({"measured table, 12 bits", table});

  auto created = SceneRenderer::create(scene, kWidth, 4);
  ASSERT_TRUE(created.ok()) << created.error();
  SceneRenderer& renderer = *created.value();
  for (const Case& c : cases) {
    OutputStage stage;
    stage.projector = optics::ProjectorModel(c.response);
    ASSERT_TRUE(renderer.output().set(stage).ok()) << c.name;
    renderer.draw(scene::SceneState{}, {0.0, kEye, view_of_unit_square()});
    const image::FloatImage light = renderer.read_rendered();
    const image::WordImage signal = renderer.output().read_signal();
    ASSERT_EQ(signal.width, light.width);
    ASSERT_EQ(signal.height, light.height);
    const optics::ProjectorModel& model = stage.projector;
    // One level: a light at a level's rounding edge may go either way in floats.
    const double one_level = 1.0 / model.levels() + 1e-6;
    double worst = 0.0;
    double lowest = 1.0;
    double highest = 0.0;
    for (int y = 0; y < light.height; ++y) {
      for (int x = 0; x < light.width; ++x) {
        for (int ch = 0; ch < 3; ++ch) {
          const double l = light.at(x, y, ch);
          lowest = std::min(lowest, l);
          highest = std::max(highest, l);
          const double sent = signal.at(x, y, ch) / 65535.0;
          worst = std::max(worst, std::abs(sent - model.signal_for(l)));
        }
      }
    }
    EXPECT_LE(worst, one_level) << c.name << ": the shader's signal is " << worst * model.levels()
                                << " levels from the model's";
    EXPECT_LT(lowest, 0.001) << c.name << ": the ramp should reach black";
    EXPECT_GT(highest, 0.99) << c.name << ": the ramp should reach white";
  }
}

// GL's box reduction of a supersampled render (render-reference, perceive's
// ideal) is the CPU's box_downsample of the same pixels: every block, the right
// way up, at a factor that is no power of two; a source of the wrong size is
// refused, not read past.
TEST_F(SceneRendererTest, BoxReductionByGlIsTheMeanOfEachBlock) {
  constexpr int kTexels = 7;  // edges between texels fall inside the 3×3 blocks
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());
  scene::Texture texture{"varied", kTexels, kTexels, {}};
  for (int i = 0; i < kTexels * kTexels; ++i) {
    for (int c = 0; c < 3; ++c) texture.rgba.push_back(static_cast<std::uint8_t>((i * 37 + c * 91) % 256));
    texture.rgba.push_back(255);
  }
  scene.textures.push_back(texture);
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 0u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  only_ambient(scene);
  auto renderer = SceneRenderer::create(scene, kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  renderer.value()->draw(scene::SceneState{}, {0.0, kEye, view_of_unit_square()});

  auto reduce = BoxReduce::make(kSize / 3, kSize / 3, 3);
  ASSERT_TRUE(reduce.ok()) << reduce.error();
  auto by_gl = reduce.value().read(renderer.value()->rendered_framebuffer());
  ASSERT_TRUE(by_gl.ok()) << by_gl.error();
  const image::FloatImage by_cpu = image::box_downsample(renderer.value()->read_rendered(), 3);
  ASSERT_EQ(by_gl.value().width, by_cpu.width);
  ASSERT_EQ(by_gl.value().height, by_cpu.height);
  float worst = 0.0f;
  float spread = 0.0f;  // the blocks differ: a flipped or shifted read cannot match
  for (std::size_t i = 0; i < by_cpu.pixels.size(); ++i) {
    worst = std::max(worst, std::abs(by_gl.value().pixels[i] - by_cpu.pixels[i]));
    spread = std::max(spread, std::abs(by_cpu.pixels[i] - by_cpu.pixels[0]));
  }
  EXPECT_LE(worst, 1e-6f);
  EXPECT_GT(spread, 0.3f);

  auto wrong = BoxReduce::make(kSize / 4, kSize / 4, 4);
  ASSERT_TRUE(wrong.ok()) << wrong.error();
  auto refused = wrong.value().read(renderer.value()->rendered_framebuffer());
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().find("was given 66×66"), std::string::npos) << refused.error();
  EXPECT_FALSE(BoxReduce::make(0, 4, 2).ok());
}

TEST_F(SceneRendererTest, MaterialTextureOutOfRangeFailsCreate) {
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 3u);
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  EXPECT_FALSE(SceneRenderer::create(scene, kSize, kSize).ok());
}

// A small emissive square at the world's origin, lit by nothing else: the
// scene an application places again (its asset id "square").
scene::SceneDefinition emissive_square() {
  scene::SceneDefinition scene;
  scene.name = "square";
  scene.asset_id = "square";
  scene::Mesh mesh = textured_quad();
  for (auto& vertex : mesh.vertices) vertex.position *= 0.1f;  // 0.2 m wide: ±3.3 pixels
  scene.meshes.push_back(std::move(mesh));
  scene.materials.emplace_back(glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(0.25f, 0.5f, 0.125f));
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  scene.lights.clear();
  scene.ambient = glm::vec3(0.0f);
  return scene;
}

scene::InstanceState square_at(double x, double y, const std::string& parent = {}) {
  scene::InstanceState instance;
  instance.asset = "square";
  instance.parent = parent;
  scene::Pose pose;
  pose.position = {x, y, 0.0};
  instance.pose = {pose, pose};
  return instance;
}

// Each visible instance of the installation's scene is drawn where its chain
// of parents puts it, with its factors on every material; a hidden one, one
// under a hidden group, or one of another asset, is not. The world point
// (0.5, 0.5) is pixel (49, 16) (top row first), the origin pixel (33, 33).
TEST_F(SceneRendererTest, LiveInstancesOfTheSceneAreDrawnWhereTheirParentsPutThem) {
  auto renderer = SceneRenderer::create(emissive_square(), kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  const auto channel = [&](const scene::SceneState& state, int x, int y, int c) {
    renderer.value()->draw(state, {0.0, kEye, view_of_unit_square()});
    return renderer.value()->read_rendered().at(x, y, c);
  };
  scene::SceneState state;
  EXPECT_NEAR(channel(state, kSize / 2, kSize / 2, 1), 0.5f, kTolerance);  // the scene where it is
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.0f, kTolerance);
  state.instances["copy"] = square_at(0.5, 0.5);
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.5f, kTolerance);
  EXPECT_NEAR(channel(state, kSize / 2, kSize / 2, 1), 0.5f, kTolerance);  // still there too
  state.instances["copy"].emissive = {2.0, 0.5, 0.0};
  EXPECT_NEAR(channel(state, kFar, kNear, 0), 0.5f, kTolerance);
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.25f, kTolerance);
  EXPECT_NEAR(channel(state, kFar, kNear, 2), 0.0f, kTolerance);
  state.instances["copy"].visible = false;
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.0f, kTolerance);

  // Under a group moved to (0.5, 0): the child's (0, 0.5) lands at (0.5, 0.5).
  state.instances.erase("copy");
  state.instances["group"] = square_at(0.5, 0.0);
  state.instances["child"] = square_at(0.0, 0.5, "group");
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.5f, kTolerance);
  state.instances["group"].visible = false;
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.0f, kTolerance);

  state.instances.clear();
  state.instances["other"] = square_at(0.5, 0.5);
  state.instances["other"].asset = "teapot";
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.0f, kTolerance);
}

// An asset an application loaded: its instances are drawn from its own
// meshes and materials once the renderer has it (before, none is), beside the
// scene's, and with its parents among the scene's instances; loaded again
// under the same id, the new content replaces the old.
TEST_F(SceneRendererTest, InstancesOfALoadedAssetAreDrawnFromItsOwnContent) {
  auto renderer = SceneRenderer::create(emissive_square(), kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  const auto channel = [&](const scene::SceneState& state, int x, int y, int c) {
    renderer.value()->draw(state, {0.0, kEye, view_of_unit_square()});
    return renderer.value()->read_rendered().at(x, y, c);
  };
  scene::SceneDefinition red = emissive_square();
  red.asset_id = "red";
  red.materials[0].emissive = glm::vec3(0.75f, 0.0f, 0.0f);
  scene::SceneState state;
  state.instances["r"] = square_at(0.5, 0.5);
  state.instances["r"].asset = "red";
  EXPECT_NEAR(channel(state, kFar, kNear, 0), 0.0f, kTolerance) << "not loaded yet: not drawn";
  ASSERT_TRUE(renderer.value()->add_asset(red).ok());
  EXPECT_NEAR(channel(state, kFar, kNear, 0), 0.75f, kTolerance);
  EXPECT_NEAR(channel(state, kFar, kNear, 1), 0.0f, kTolerance);
  EXPECT_NEAR(channel(state, kSize / 2, kSize / 2, 1), 0.5f, kTolerance) << "the scene is still drawn";
  // Under an instance of the scene moved to (0.5, 0): (0, 0.5) lands at (0.5, 0.5).
  state.instances["group"] = square_at(0.5, 0.0);
  state.instances["r"].pose = square_at(0.0, 0.5).pose;
  state.instances["r"].parent = "group";
  EXPECT_NEAR(channel(state, kFar, kNear, 0), 0.75f, kTolerance);
  red.materials[0].emissive = glm::vec3(0.0f, 0.0f, 0.5f);
  ASSERT_TRUE(renderer.value()->add_asset(red).ok());
  EXPECT_NEAR(channel(state, kFar, kNear, 0), 0.0f, kTolerance);
  EXPECT_NEAR(channel(state, kFar, kNear, 2), 0.5f, kTolerance);
  scene::SceneDefinition broken = red;
  broken.asset_id = "broken";
  broken.instances[0].mesh = 7;
  EXPECT_FALSE(renderer.value()->add_asset(broken).ok());
}

// A point light an application added lights the scene as the scene's own
// would: where the state puts it, as bright as it says, not when it is off,
// not by a node whose share leaves it out, and never over one of the scene's
// own lights (index 0 here: a state that names it is not drawn from).
TEST_F(SceneRendererTest, APointLightAddedLightsTheSceneWhereTheStatePutsIt) {
  scene::SceneDefinition scene;
  scene.meshes.push_back(textured_quad());  // fills the view, facing the viewer
  scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f));
  scene.instances.push_back({0, 0, std::nullopt, glm::dmat4(1.0)});
  scene.lights = {{{0.0, 0.0, 1.0}, glm::vec3(0.0f), 0.0f}};  // the scene's own: dark
  scene.ambient = glm::vec3(0.0f);
  auto renderer = SceneRenderer::create(scene, kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  const auto green = [&](const scene::SceneState& state, int x, int y) {
    renderer.value()->draw(state, {0.0, kEye, view_of_unit_square()});
    return renderer.value()->read_rendered().at(x, y, 1);
  };
  const int centre = kSize / 2;
  scene::SceneState state;
  EXPECT_NEAR(green(state, centre, centre), 0.0f, kTolerance);
  // 0.5 m in front of the upper right quarter: brightest there.
  state.point_lights[1] = {{0.5, 0.5, 0.5}, {0.0, 1.0, 0.0}, 0.5};
  const float lit = green(state, kFar, kNear);
  EXPECT_GT(lit, 0.1f);
  EXPECT_LT(green(state, kNear, kFar), 0.5f * lit) << "the far corner is lit less";
  state.point_lights[1].intensity = 1.0;
  EXPECT_NEAR(green(state, kFar, kNear), 2.0f * lit, 0.02f * lit) << "twice the intensity, twice the light";
  state.point_lights[1].position = {-0.5, -0.5, 0.5};
  EXPECT_GT(green(state, kNear, kFar), 1.5f * lit) << "moved to the lower left";
  state.lights_off = {1};
  EXPECT_NEAR(green(state, kNear, kFar), 0.0f, kTolerance) << "off";
  state.lights_off.clear();
  const std::vector<std::uint32_t> only_own{0};
  renderer.value()->set_lights(only_own);
  EXPECT_NEAR(green(state, kNear, kFar), 0.0f, kTolerance) << "a share without it";
  const std::vector<std::uint32_t> with_it{0, 1};
  renderer.value()->set_lights(with_it);
  EXPECT_GT(green(state, kNear, kFar), 1.5f * lit);
  scene::SceneState over_own;
  over_own.point_lights[0] = {{0.0, 0.0, 0.5}, {1.0, 1.0, 1.0}, 1.0};
  EXPECT_NEAR(green(over_own, centre, centre), 0.0f, kTolerance) << "the scene's own light 0 is dark";
}

// An instance with its own animation clock draws its asset's animated objects
// at its times, not where the scene's time has them in the state: the square
// rides object 7, which an animation carries 1 m along x a second.
TEST_F(SceneRendererTest, AnInstancesOwnAnimationTimesPlaceWhatRidesTheAnimation) {
  scene::SceneDefinition square = emissive_square();
  square.instances[0].object = 7u;
  square.objects.push_back({7u, "slider", [](double t) {
                              scene::Pose pose;
                              pose.position.x = t;
                              return pose;
                            }});
  auto renderer = SceneRenderer::create(square, kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  const auto green = [&](const scene::SceneState& state, int x, int y) {
    renderer.value()->draw(state, {0.0, kEye, view_of_unit_square()});
    return renderer.value()->read_rendered().at(x, y, 1);
  };
  scene::SceneState state;
  state.objects[7] = {};  // the scene's time: the slider at the origin
  state.instances["copy"] = square_at(0.0, 0.5);
  EXPECT_NEAR(green(state, kSize / 2, kNear), 0.5f, kTolerance) << "the copy where the state's slider puts it";
  EXPECT_NEAR(green(state, kFar, kNear), 0.0f, kTolerance);
  state.instances["copy"].animation = scene::AnimationTimes{0.5, 0.5};
  EXPECT_NEAR(green(state, kFar, kNear), 0.5f, kTolerance) << "its own time: the slider 0.5 m on";
  EXPECT_NEAR(green(state, kSize / 2, kNear), 0.0f, kTolerance);
  EXPECT_NEAR(green(state, kSize / 2, kSize / 2), 0.5f, kTolerance) << "the installation's square stays";
}

// A DLP projector's fields draw what does not move once for every field: a
// live instance is drawn in each field all the same.
TEST_F(SceneRendererTest, LiveInstancesAreDrawnInEveryColourField) {
  auto renderer = SceneRenderer::create(emissive_square(), kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  scene::SceneState state;
  state.instances["copy"] = square_at(0.5, 0.5);
  const Viewpoint view{0.0, kEye, view_of_unit_square()};
  const FieldPass passes[] = {{view, true, false, false}, {view, false, true, false}, {view, false, false, true}};
  renderer.value()->draw_fields(state, passes);
  const auto image = renderer.value()->read_rendered();
  const float expected[] = {0.25f, 0.5f, 0.125f};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(image.at(kFar, kNear, c), expected[c], kTolerance) << "channel " << c;
    EXPECT_NEAR(image.at(kSize / 2, kSize / 2, c), expected[c], kTolerance) << "channel " << c;
  }
}

// The navigation carries the viewer through the world (render/viewpoint.h):
// world ← installation turned a quarter about the screen's normal, the
// world's (-0.5, 0.5) is in front of the room's (0.5, 0.5), while the world's
// origin stays at the room's. Without one, the view is the room's to the bit.
TEST_F(SceneRendererTest, TheNavigationCarriesTheViewerThroughTheWorld) {
  auto renderer = SceneRenderer::create(emissive_square(), kSize, kSize);
  ASSERT_TRUE(renderer.ok()) << renderer.error();
  scene::SceneState state;
  state.instances["copy"] = square_at(-0.5, 0.5);
  const Viewpoint room{0.0, kEye, view_of_unit_square()};
  EXPECT_EQ(seen_in_world(state, 0.0, kEye, room.frustum).frustum.view, room.frustum.view);
  scene::Pose turned;
  turned.rotation = glm::angleAxis(glm::radians(90.0), glm::dvec3(0.0, 0.0, 1.0));
  state.navigation = {turned, turned};
  renderer.value()->draw(state, seen_in_world(state, 0.0, kEye, room.frustum));
  const auto image = renderer.value()->read_rendered();
  EXPECT_NEAR(image.at(kFar, kNear, 1), 0.5f, kTolerance) << "the world's (-0.5, 0.5) at the room's (0.5, 0.5)";
  EXPECT_NEAR(image.at(kNear, kFar, 1), 0.0f, kTolerance);
  EXPECT_NEAR(image.at(kSize / 2, kSize / 2, 1), 0.5f, kTolerance) << "the world's origin where the room's is";
  // Carried half a metre along the world's x: what was at the centre moves left.
  scene::Pose moved;
  moved.position = {0.5, 0.0, 0.0};
  state.navigation = {moved, moved};
  state.instances.clear();
  renderer.value()->draw(state, seen_in_world(state, 0.0, kEye, room.frustum));
  const auto shifted = renderer.value()->read_rendered();
  EXPECT_NEAR(shifted.at(kSize / 2, kSize / 2, 1), 0.0f, kTolerance);
  EXPECT_NEAR(shifted.at(kSize / 2 - 16, kSize / 2, 1), 0.5f, kTolerance) << "the world's origin at the room's -0.5";
}

}  // namespace
}  // namespace optique::render
