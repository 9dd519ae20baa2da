// Frame-rate up-conversion in the scene renderer (render/up_converter.h): frames
// between key frames built from the key frames' pixels along the exact motion
// field, measured against full renders of the same moments. Each case writes
// the frames it compares (and their difference) under the test's output folder
// when it fails.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "geometry/projection.h"
#include "image/compare.h"
#include "image/image_io.h"
#include "process.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "up_experiment.h"

namespace optique::render {
namespace {

constexpr int kWidth = 256;
constexpr int kHeight = 192;
const glm::dvec3 kEye{0.0, 0.0, 2.0};
constexpr double kFrame = 1.0 / 60.0;  // seconds per display frame

// The viewer 2 m in front of a 2 m × 1.5 m screen in the z = 0 plane.
geometry::Frustum view() {
  geometry::WorldRect rect;
  rect.lower_left = {-1.0, -0.75, 0.0};
  rect.width = 2.0;
  rect.height = 1.5;
  auto frustum = geometry::off_axis_frustum(rect, kEye, 0.1, 10.0);
  EXPECT_TRUE(frustum.ok());
  return frustum.ok() ? frustum.value() : geometry::Frustum{};
}

// A square `side` metres wide in the z = 0 plane, uv over it, facing +z.
scene::Mesh square(float side) {
  scene::Mesh mesh;
  mesh.name = "square";
  const float h = side / 2.0f;
  const glm::vec3 n(0.0f, 0.0f, 1.0f);
  mesh.vertices = {{{-h, h, 0.0f}, n, {0.0f, 0.0f}},
                   {{h, h, 0.0f}, n, {1.0f, 0.0f}},
                   {{h, -h, 0.0f}, n, {1.0f, 1.0f}},
                   {{-h, -h, 0.0f}, n, {0.0f, 1.0f}}};
  mesh.indices = {0, 3, 2, 0, 2, 1};
  return mesh;
}

// Smooth colour waves (a few periods across, no edges inside): what a key
// frame's pixels resample without losing detail the full render has.
scene::Texture waves(int periods_u, int periods_v) {
  constexpr int kSide = 128;
  scene::Texture texture{"waves", kSide, kSide, {}};
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      const double u = (x + 0.5) / kSide;
      const double v = (y + 0.5) / kSide;
      const double tau = 2.0 * std::numbers::pi;
      const double r = 0.5 + 0.35 * std::sin(tau * periods_u * u) * std::cos(tau * periods_v * v);
      const double g = 0.5 + 0.35 * std::cos(tau * periods_u * u + 1.0);
      const double b = 0.5 + 0.35 * std::sin(tau * periods_v * v + 2.0);
      for (double c : {r, g, b}) texture.rgba.push_back(static_cast<std::uint8_t>(std::lround(255.0 * c)));
      texture.rgba.push_back(255);
    }
  }
  return texture;
}

// What moves: object 1's pose at a time in seconds.
using Motion = std::function<scene::Pose(double)>;

// The scene's state at display frame `n`: poses now and a frame later, or
// without object 1 when `present` says it is not there.
scene::SceneState state_at(const Motion& motion, int n, const std::function<bool(int)>& present = {}) {
  scene::SceneState state;
  state.eye_now = state.eye_next = kEye;
  if (!present || present(n)) state.objects[1] = {motion(n * kFrame), motion((n + 1) * kFrame)};
  return state;
}

class UpConversion : public ::testing::Test {
 protected:
  void SetUp() override {
    auto context = make_headless_context();
    ASSERT_TRUE(context.ok()) << "no headless OpenGL context: " << context.error();
    context_ = std::move(context).value();
  }

  // A textured square on object 1 (lit by ambient only: its colour is its
  // texture), over a textured still backdrop when `backdrop`.
  static scene::SceneDefinition squares(bool backdrop) {
    scene::SceneDefinition scene;
    scene.name = "up-conversion squares";
    scene.meshes = {square(0.8f), square(1.9f)};
    scene.textures = {waves(3, 2), waves(2, 3)};
    scene.materials.emplace_back(glm::vec3(1.0f), 0.0f, 1.0f, glm::vec3(0.0f), 0u);
    scene.materials.emplace_back(glm::vec3(0.6f), 0.0f, 1.0f, glm::vec3(0.0f), 1u);
    scene.instances.push_back({0, 0, 1u, glm::dmat4(1.0)});
    if (backdrop) {
      scene.instances.push_back({1, 1, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -0.3))});
    }
    scene.objects.push_back({1, "square", {}});
    scene.lights.clear();
    scene.ambient = glm::vec3(1.0f);
    scene.background = glm::vec3(0.05f, 0.1f, 0.15f);
    return scene;
  }

  void make(const scene::SceneDefinition& scene, int samples = 1) {
    auto renderer = SceneRenderer::create(scene, kWidth, kHeight, DepthFormat::float32, samples);
    ASSERT_TRUE(renderer.ok()) << renderer.error();
    renderer_ = std::move(renderer).value();
    auto prepared = renderer_->prepare_up_conversion();
    ASSERT_TRUE(prepared.ok()) << prepared.error();
  }

  // The full render of a state (linear light, before the output stage).
  image::FloatImage full(const scene::SceneState& state) {
    renderer_->draw(state, {0.0, kEye, view()});
    return renderer_->read_rendered();
  }

  // Draws `state` and keeps it as key `slot`.
  void key(int slot, const scene::SceneState& state) {
    const geometry::Frustum f = view();
    renderer_->draw(state, {0.0, kEye, f});
    renderer_->up_conversion().keep_key(slot, {state, 0.0, f.projection * f.view});
  }

  image::FloatImage between(const scene::SceneState& state, const up::BetweenFrame& frame,
                            up::BetweenReport* report = nullptr) {
    const up::BetweenReport r = renderer_->up_conversion().draw_between(state, {0.0, kEye, view()}, frame);
    if (report) *report = r;
    return renderer_->read_rendered();
  }

  // PSNR_Y (the paper's) of `actual` against `expected`; both written with
  // their difference when it is below `bar`.
  double psnr_y(const image::FloatImage& actual, const image::FloatImage& expected, const std::string& name,
                double bar) {
    auto c = image::compare(actual, expected);
    EXPECT_TRUE(c.ok());
    if (!c.ok()) return 0.0;
    if (c.value().psnr_y_weighted < bar) {
      const testing::ScratchDir dir_scratch("optique-up-conversion");
      const std::string dir = dir_scratch.string();
      (void)image::write_exr(dir + "/" + name + "-actual.exr", actual);
      (void)image::write_exr(dir + "/" + name + "-expected.exr", expected);
      (void)image::write_exr(dir + "/" + name + "-difference.exr", image::difference(actual, expected, 4.0f));
      ADD_FAILURE() << name << ": " << c.value().psnr_y_weighted << " dB; the frames and their difference (×4) in "
                    << dir;
    }
    return c.value().psnr_y_weighted;
  }

  std::unique_ptr<GlContext> context_;
  std::unique_ptr<SceneRenderer> renderer_;
};

const Motion kStill = [](double) { return scene::Pose{glm::dvec3(0.1, 0.05, 0.0)}; };
// 2.5 px per frame to the right (the screen: 128 px per metre at the plane).
const Motion kTranslating = [](double t) {
  return scene::Pose{glm::dvec3(-0.3 + t * 60.0 * 2.5 / 128.0, 0.02 + t * 60.0 * 0.7 / 128.0, 0.0)};
};
// Turning in its plane, 3° per frame; and about the vertical, 2° per frame.
const Motion kTurning = [](double t) {
  return scene::Pose{glm::dvec3(0.05, 0.0, 0.0), glm::angleAxis(glm::radians(3.0 * 60.0 * t), glm::dvec3(0, 0, 1))};
};
const Motion kTurningAway = [](double t) {
  return scene::Pose{glm::dvec3(0.0, 0.0, 0.1),
                     glm::angleAxis(glm::radians(10.0 + 2.0 * 60.0 * t), glm::dvec3(0, 1, 0))};
};

// Multisampled, the pixels at the squares' edges hold two surfaces each; they
// moved alike (not at all), so each is the key frame's pixel as it is.
TEST_F(UpConversion, WithoutMotionTheFrameBetweenIsTheKeyFrame) {
  for (const int samples : {1, 4}) {
    make(squares(true), samples);
    key(0, state_at(kStill, 0));
    const image::FloatImage key_image = renderer_->read_rendered();
    for (up::BetweenMethod method : {up::BetweenMethod::motion, up::BetweenMethod::average}) {
      if (method == up::BetweenMethod::average) key(1, state_at(kStill, 4));
      up::BetweenReport report;
      const image::FloatImage b =
          between(state_at(kStill, 2), {method, 0, method == up::BetweenMethod::average, 0.5}, &report);
      auto c = image::compare(b, key_image);
      ASSERT_TRUE(c.ok());
      const std::string name = std::string(method == up::BetweenMethod::motion ? "motion" : "average") + ", " +
                               std::to_string(samples) + " sample(s)";
      EXPECT_LE(c.value().max_abs_error, 1e-6) << name;
      // Multisampled, the squares' outlines (measured: 595 px, 1.2 %).
      EXPECT_EQ(report.unseen_pixels, 0) << name;
    }
  }
}

TEST_F(UpConversion, TranslatingAndTurningSquaresMatchTheirFullRenders) {
  struct Case {
    const char* name;
    Motion motion;
    int samples = 1;  // multisampled: each sample of an edge from its own surface
    // The issue's bar at one sample; multisampled, measured 61-66 dB (55-62
    // turning away), the bar below that.
    double bar = 40.0;
  };
  for (const Case& c :
       {Case{"translating", kTranslating}, Case{"turning", kTurning}, Case{"turning-away", kTurningAway},
        Case{"translating, 4 samples", kTranslating, 4, 55.0}, Case{"turning, 4 samples", kTurning, 4, 55.0},
        Case{"turning-away, 4 samples", kTurningAway, 4, 50.0}}) {
    make(squares(false), c.samples);
    key(0, state_at(c.motion, 0));
    double worst = 1e9;
    for (int n = 1; n <= 3; ++n) {  // 4:1, extrapolated from the key frame
      const image::FloatImage b = between(state_at(c.motion, n), {up::BetweenMethod::motion, 0, false, 0.0});
      const image::FloatImage reference = full(state_at(c.motion, n));
      const double db = psnr_y(b, reference, std::string(c.name) + "-" + std::to_string(n), c.bar);
      std::cout << c.name << " frame " << n << ": " << db << " dB\n";
      EXPECT_GE(db, c.bar) << c.name << " frame " << n;
      worst = std::min(worst, db);
    }
    // What the motion field is worth: the key frame shown again is far off.
    const image::FloatImage key_again = full(state_at(c.motion, 0));
    auto repeated = image::compare(key_again, full(state_at(c.motion, 3)));
    ASSERT_TRUE(repeated.ok());
    EXPECT_LT(repeated.value().psnr_y_weighted, worst - 15.0) << c.name;
  }
}

// The square moves over a still backdrop: behind it the backdrop comes into
// view where the key frame saw the square. Those pixels are found (their count
// is the uncovered area), and shaded anew they match the full render; left as
// they were they show the square.
TEST_F(UpConversion, UncoveredBackdropIsFoundAndShadedAnew) {
  make(squares(true));
  key(0, state_at(kTranslating, 0));
  for (int n = 1; n <= 3; ++n) {
    const scene::SceneState state = state_at(kTranslating, n);
    up::BetweenReport report;
    const image::FloatImage shaded = between(state, {up::BetweenMethod::motion, 0, false, 0.0}, &report);
    const image::FloatImage reference = full(state);
    const double db = psnr_y(shaded, reference, "uncovered-" + std::to_string(n), 40.0);
    // The square is 0.8 m at 128 px per metre and moves (2.5, 0.7) px per frame;
    // uncovered: the L its trailing edges leave.
    const double side = 0.8 * 128.0;
    const double dx = 2.5 * n;
    const double dy = 0.7 * n;
    const double uncovered = side * dx + side * dy - dx * dy;
    std::cout << "frame " << n << ": " << db << " dB, " << report.unseen_pixels << " unseen pixels (uncovered "
              << uncovered << ")\n";
    EXPECT_GE(db, 40.0);
    EXPECT_NEAR(static_cast<double>(report.unseen_pixels), uncovered, 0.1 * uncovered + 2.0 * side);
    const image::FloatImage left = between(state, {up::BetweenMethod::motion, 0, false, 0.0, false});
    auto c = image::compare(left, reference);
    ASSERT_TRUE(c.ok());
    EXPECT_LT(c.value().psnr_y_weighted, db - 10.0) << "unseen pixels left as the key frame had them";
  }
}

// An object that was not in the scene at the key frame: no key frame saw any
// of it, all of it is shaded anew.
TEST_F(UpConversion, AnObjectThatEntersIsShadedAnew) {
  make(squares(true));
  const auto after_first = [](int n) { return n >= 2; };
  key(0, state_at(kTranslating, 0, after_first));
  const scene::SceneState state = state_at(kTranslating, 3, after_first);
  up::BetweenReport report;
  const image::FloatImage b = between(state, {up::BetweenMethod::motion, 0, false, 0.0}, &report);
  EXPECT_GE(psnr_y(b, full(state), "entering", 40.0), 40.0);
  const double area = 0.8 * 128.0 * 0.8 * 128.0;
  EXPECT_NEAR(static_cast<double>(report.unseen_pixels), area, 0.05 * area);
}

// The square comes into view across the image's left edge: what the key frame
// could not see (beyond its edge) is shaded anew, the strip that came in.
TEST_F(UpConversion, WhatComesIntoViewIsShadedAnew) {
  make(squares(false));
  const Motion entering = [](double t) { return scene::Pose{glm::dvec3(-1.2 + t * 60.0 * 2.5 / 128.0, 0.0, 0.0)}; };
  key(0, state_at(entering, 0));
  for (int n = 1; n <= 3; ++n) {
    const scene::SceneState state = state_at(entering, n);
    up::BetweenReport report;
    const image::FloatImage b = between(state, {up::BetweenMethod::motion, 0, false, 0.0}, &report);
    const double db = psnr_y(b, full(state), "entering-view-" + std::to_string(n), 40.0);
    const double strip = 0.8 * 128.0 * 2.5 * n;  // the square's height × how far it came in
    std::cout << "frame " << n << ": " << db << " dB, " << report.unseen_pixels << " unseen pixels (strip " << strip
              << ")\n";
    EXPECT_GE(db, 40.0);
    EXPECT_NEAR(static_cast<double>(report.unseen_pixels), strip, 0.1 * strip + 0.8 * 128.0);
  }
}

// Between two key frames: what the first no longer shows the second does, so
// nothing needs shading; the average of the two (the paper's baseline) is far
// below.
TEST_F(UpConversion, BetweenTwoKeyFramesNothingIsUnseen) {
  make(squares(true));
  key(0, state_at(kTranslating, 0));
  key(1, state_at(kTranslating, 4));
  for (int n = 1; n <= 3; ++n) {
    const scene::SceneState state = state_at(kTranslating, n);
    const image::FloatImage reference = full(state);
    up::BetweenReport report;
    const image::FloatImage b = between(state, {up::BetweenMethod::motion, 0, true, n / 4.0, false}, &report);
    const double db = psnr_y(b, reference, "two-keys-" + std::to_string(n), 40.0);
    const image::FloatImage average = between(state, {up::BetweenMethod::average, 0, true, n / 4.0, false});
    auto c = image::compare(average, reference);
    ASSERT_TRUE(c.ok());
    std::cout << "frame " << n << ": " << db << " dB (average " << c.value().psnr_y_weighted << " dB), "
              << report.unseen_pixels << " unseen pixels\n";
    EXPECT_GE(db, 40.0);
    EXPECT_LE(report.unseen_pixels, 2 * 0.8 * 128.0) << "at most the edges";
    EXPECT_LT(c.value().psnr_y_weighted, db - 11.0);
  }
}

// A surface turned more than 20° since the key frame (up::kMostTurn) faces the
// lights and the eye otherwise than it was shaded: it is shaded anew, not
// taken. The square turns 10° a frame about the vertical: a frame on, it is
// taken (its edges only unseen); three frames on, all of it is shaded anew.
TEST_F(UpConversion, ASurfaceTurnedFurtherThanTheLimitIsShadedAnew) {
  const Motion spinning = [](double t) {
    return scene::Pose{glm::dvec3(0.0, 0.0, 0.1),
                       glm::angleAxis(glm::radians(10.0 + 10.0 * 60.0 * t), glm::dvec3(0, 1, 0))};
  };
  make(squares(false));
  key(0, state_at(spinning, 0));
  const double side = 0.8 * 128.0;
  for (const int n : {1, 3}) {
    const scene::SceneState state = state_at(spinning, n);
    up::BetweenReport report;
    const image::FloatImage b = between(state, {up::BetweenMethod::motion, 0, false, 0.0}, &report);
    const double db = psnr_y(b, full(state), "turned-" + std::to_string(n), 40.0);
    // The square's area on the image at 40°: its width foreshortened by cos.
    const double area = side * side * std::cos(glm::radians(10.0 + 10.0 * n));
    std::cout << "turned " << 10 * n << "° since the key frame: " << report.unseen_pixels << " unseen pixels of about "
              << area << ", " << db << " dB\n";
    if (n == 1) {
      EXPECT_LE(report.unseen_pixels, 4.0 * side) << "at most its edges";
    } else {
      EXPECT_GE(report.unseen_pixels, 0.9 * area) << "all of it shaded anew";
    }
    EXPECT_GE(db, 40.0);
  }
}

// Between two key frames the frame weighs each by how near it is: a quarter of
// the way, three parts of the first to one of the second. The squares stand
// still and a light comes on between the key frames, so the two differ only in
// brightness and the frame between is their mix (weights swapped, it is the
// other mix, far off).
TEST_F(UpConversion, TheNearerKeyFrameWeighsMore) {
  scene::SceneDefinition lit = squares(true);
  lit.ambient = glm::vec3(0.2f);
  lit.lights.push_back({glm::dvec3(0.3, 0.4, 1.5), glm::vec3(1.0f), 2.0f});
  make(lit);
  scene::SceneState dark = state_at(kStill, 0);
  dark.lights_off = {0};
  key(0, dark);
  const image::FloatImage first = renderer_->read_rendered();
  key(1, state_at(kStill, 4));
  const image::FloatImage second = renderer_->read_rendered();
  for (const double t : {0.25, 0.75}) {
    const image::FloatImage b = between(state_at(kStill, 1), {up::BetweenMethod::motion, 0, true, t, false});
    image::FloatImage mix = first;
    for (std::size_t i = 0; i < mix.pixels.size(); ++i) {
      mix.pixels[i] = static_cast<float>((1.0 - t) * first.pixels[i] + t * second.pixels[i]);
    }
    // Measured: identical but for float rounding (160 dB); the other mix 32 dB.
    const double db = psnr_y(b, mix, "weights-" + std::to_string(t), 60.0);
    std::cout << "a " << t << " of the way: " << db << " dB against the mix\n";
    EXPECT_GE(db, 60.0);
  }
}

}  // namespace
}  // namespace optique::render

namespace optique::bench::upconv {
namespace {

StageScene scene_named(const std::string& name) {
  for (const StageScene& s : paper_scenes()) {
    if (s.name == name) return s;
  }
  ADD_FAILURE() << "no scene " << name;
  return {};
}

std::string kinds(const SceneResult& result) {
  std::string out;
  for (const FrameResult& f : result.frames) out += std::string(up::to_string(f.kind)).substr(0, 1);
  return out;
}

class UpConvertingPipeline : public ::testing::Test {
 protected:
  void SetUp() override {
    auto context = render::make_headless_context();
    ASSERT_TRUE(context.ok()) << "no headless OpenGL context: " << context.error();
    context_ = std::move(context).value();
  }
  std::unique_ptr<render::GlContext> context_;
};

// The pipeline a node builds: every display frame drawn, a key frame every
// four, the frames between close to the full renders of their moments; the key
// frames drawn ahead are shown exactly as drawn.
TEST_F(UpConvertingPipeline, DrawsEveryDisplayFrameFromKeyFramesEveryFour) {
  StageScene scene = scene_named("cube-slow-rotation");
  scene.frame_rate = 60.0;
  for (config::UpMode mode : {config::UpMode::interpolate, config::UpMode::extrapolate}) {
    auto result = measure(scene, {config::UpMethod::motion, mode, 4, 0.0}, 13, 160, 120);
    ASSERT_TRUE(result.ok()) << result.error();
    const SceneResult& r = result.value();
    std::cout << config::to_string(mode) << ": " << kinds(r) << ", frames between " << r.mean_between_psnr << " dB\n";
    EXPECT_EQ(kinds(r), mode == config::UpMode::interpolate ? "kbbbsbbbsbbbs" : "kbbbkbbbkbbbk");
    for (const FrameResult& f : r.frames) {
      if (f.kind != up::FrameKind::between) {
        EXPECT_TRUE(std::isinf(f.psnr_y)) << "frame " << f.frame << " is a key frame: drawn as the full render is";
      }
    }
    // Measured 49.0 dB extrapolated and 56.0 interpolated, as displayed: each
    // held to its own, 4 dB under (a fault in one mode shows in its bar).
    EXPECT_GE(r.mean_between_psnr, mode == config::UpMode::interpolate ? 52.0 : 45.0);
  }
}

// Key frames drawn a band a frame (spread): extrapolated, every frame after the
// first is built between (each from a key frame 4-7 frames old); interpolated,
// once the scenes sent ahead reach far enough, key frames are only shown, and
// one assembled from its bands is the full render exactly. Multisampled too
// (each band's samples, and which of its pixels hold two surfaces, kept).
TEST_F(UpConvertingPipeline, SpreadKeyFramesAreAssembledFromTheirBands) {
  StageScene scene = scene_named("cube-slow-rotation");
  scene.frame_rate = 60.0;
  for (const int samples : {1, 4}) {
    for (config::UpMode mode : {config::UpMode::interpolate, config::UpMode::extrapolate}) {
      auto result = measure(scene, {config::UpMethod::motion, mode, 4, 0.0, true, samples}, 20, 160, 120);
      ASSERT_TRUE(result.ok()) << result.error();
      const SceneResult& r = result.value();
      std::cout << config::to_string(mode) << ", spread, " << samples << " sample(s): " << kinds(r)
                << ", frames between " << r.mean_between_psnr << " dB, worst " << r.frames[r.hardest].psnr_y << " dB\n";
      EXPECT_EQ(kinds(r), mode == config::UpMode::interpolate ? "kkkkbbbsbbbsbbbsbbbs" : "kbbbbbbbbbbbbbbbbbbb");
      for (const FrameResult& f : r.frames) {
        if (f.kind != up::FrameKind::between) {
          EXPECT_TRUE(std::isinf(f.psnr_y)) << "frame " << f.frame << " shows a key frame: as the full render is";
        }
      }
      // Measured 56.1 dB interpolated; 42.6 extrapolated (49.0 with each key frame
      // drawn at once: the key frames are older).
      EXPECT_GE(r.mean_between_psnr, mode == config::UpMode::interpolate ? 48.0 : 38.0);
    }
  }
}

// The up-conversion paper's scene set at 4:1, each framed so that the average
// of the key frames around a frame (its baseline) lands within 3 dB of the
// paper's: interpolation beats that average by at least the paper's 11 dB over
// the set, and no scene falls below 30 dB; extrapolation reported beside it.
TEST_F(UpConvertingPipeline, ThePaperScenesAt4To1) {
  double average_sum = 0.0;
  double interpolate_sum = 0.0;
  int scenes = 0;
  for (const StageScene& scene : paper_scenes()) {
    const auto run = [&](config::UpMethod method, config::UpMode mode) {
      auto result = measure(scene, {method, mode, 4, 0.0}, 24, 320, 240);
      EXPECT_TRUE(result.ok()) << scene.name << ": " << (result.ok() ? "" : result.error());
      return result.ok() ? std::move(result).value() : SceneResult{};
    };
    const SceneResult average = run(config::UpMethod::average, config::UpMode::interpolate);
    const SceneResult interpolated = run(config::UpMethod::motion, config::UpMode::interpolate);
    const SceneResult extrapolated = run(config::UpMethod::motion, config::UpMode::extrapolate);
    if (interpolated.frames.empty() || interpolated.hardest_image.empty()) continue;  // failed above
    const FrameResult& hardest = interpolated.frames[interpolated.hardest];
    std::cout << scene.name << " (" << scene.screen_width << " m, " << scene.frame_rate << " Hz): average "
              << average.mean_between_psnr << " dB (paper " << scene.paper_average << "), interpolated "
              << interpolated.mean_between_psnr << " dB (paper " << scene.paper_motion << "), extrapolated "
              << extrapolated.mean_between_psnr << " dB; hardest frame " << hardest.frame << " at " << hardest.psnr_y
              << " dB, " << 100.0 * hardest.unseen_share << " % shaded anew\n";
    EXPECT_NEAR(average.mean_between_psnr, scene.paper_average, 3.0) << scene.name << ": the framing";
    EXPECT_GE(interpolated.mean_between_psnr, 30.0) << scene.name;
    average_sum += average.mean_between_psnr;
    interpolate_sum += interpolated.mean_between_psnr;
    ++scenes;
  }
  ASSERT_EQ(scenes, 9);
  std::cout << "over the set: average " << average_sum / scenes << " dB, interpolated " << interpolate_sum / scenes
            << " dB\n";
  EXPECT_GE((interpolate_sum - average_sum) / scenes, 11.0);
}

// Hard cases, each a cut the key frames must not be carried across: the viewer
// jumps a metre between two frames; ten of the twenty lights go dark between two
// key frames. Every frame, before and after, is near its full render (without
// the cut rule the frames after the lights went dark keep their light: 18.5 dB
// extrapolated, 22.9 interpolated; the jump's geometry the motion field follows
// exactly, 43.6 dB), and, extrapolated, the frame of the cut is a key frame
// drawn at once.
TEST_F(UpConvertingPipeline, NoFrameMixesTheTwoSidesOfACut) {
  struct Cut {
    const char* name;
    StageScene scene;
    std::uint64_t frame;  // the first frame after the cut
  };
  StageScene jump{"viewer jumps", "cube-slow-rotation", "", 1.0, 60.0, 0.0, 0.0, 0.0, {}, {}};
  jump.viewer_json = R"({"path": [{"time": 0, "position": [0, 1.2, 2]}, {"time": 0.225, "position": [0, 1.2, 2]},
                                  {"time": 0.2333, "position": [0.8, 1.5, 1.6]}, {"time": 10, "position": [0.8, 1.5, 1.6]}]})";
  StageScene dark{"lights go dark", "many-lights", "", 3.2, 60.0, 0.0, 0.0, 0.0, {}, {}};
  dark.scene_json = R"("light_switches": [{"time": 0.1, "off": "0-9"}])";
  for (const Cut& cut : {Cut{"viewer jumps", jump, 14}, Cut{"lights go dark", dark, 6}}) {
    for (config::UpMode mode : {config::UpMode::interpolate, config::UpMode::extrapolate}) {
      auto result = measure(cut.scene, {config::UpMethod::motion, mode, 4, 0.0}, 16, 160, 120);
      ASSERT_TRUE(result.ok()) << result.error();
      std::cout << cut.name << ", " << config::to_string(mode) << ": " << kinds(result.value()) << ", worst "
                << result.value().frames[result.value().hardest].psnr_y << " dB\n";
      for (const FrameResult& f : result.value().frames) {
        EXPECT_GE(f.psnr_y, 35.0) << cut.name << " frame " << f.frame;
        // Extrapolated, the cut's frame is a key frame drawn at once; interpolated,
        // it may come from the key frame drawn ahead alone, which is on its side.
        if (f.frame == cut.frame && mode == config::UpMode::extrapolate) {
          EXPECT_EQ(f.kind, up::FrameKind::key) << cut.name;
        }
      }
    }
  }
}

// A floor the frames between cannot keep: the key frames come every frame.
TEST_F(UpConvertingPipeline, TheAdaptiveRatioDrawsMoreKeyFramesBelowTheFloor) {
  StageScene scene = scene_named("wheel-rotation");
  scene.frame_rate = 30.0;
  auto result = measure(scene, {config::UpMethod::motion, config::UpMode::extrapolate, 4, 99.0}, 12, 160, 120);
  ASSERT_TRUE(result.ok()) << result.error();
  std::cout << kinds(result.value()) << "\n";
  EXPECT_EQ(result.value().frames.back().ratio, 1);
  EXPECT_EQ(kinds(result.value()).substr(9), "kkk");
}

}  // namespace
}  // namespace optique::bench::upconv
