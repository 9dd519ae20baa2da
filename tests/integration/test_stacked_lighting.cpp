// The lighting split of configs/stacked-lighting-3.json drawn in-process: three
// projectors, each with its share of the 20 lights and its own response, black
// level and brightness, against one projector drawing everything (Majumder &
// Welch, seed 004: the screen adds the light; m projectors show more levels).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "config/geometry.h"
#include "config/load.h"
#include "image/texture_decode.h"
#include "master/stacked_groups.h"
#include "optics/projector_model.h"
#include "render/gl_context.h"
#include "render/projector_view.h"
#include "render/scene_renderer.h"
#include "scene/load_scene.h"

namespace optique {
namespace {

const std::string kConfig = std::string(OPTIQUE_SOURCE_DIR) + "/configs/stacked-lighting-3.json";

struct Drawn {
  image::FloatImage rendered;  // linear, before the output pass
  image::FloatImage emitted;   // the light the projector emits (quantized signal through its model)
};

class StackedLighting : public ::testing::Test {
 protected:
  void SetUp() override {
    auto context = render::make_headless_context();
    ASSERT_TRUE(context) << context.error();
    context_ = std::move(context).value();
    auto loaded = config::load_installation(kConfig);
    ASSERT_TRUE(loaded) << loaded.error();
    config_ = std::move(loaded).value();
    auto scene = scene::load_scene(config_.installation.scene(), config_.directory, image::decode_texture);
    ASSERT_TRUE(scene) << scene.error();
    scene_ = std::move(scene).value().definition;
    for (const auto& object : scene_.objects) {
      state_.objects[object.id] = {object.pose_at(1.0), object.pose_at(1.0)};
    }
    const auto& eye = config_.installation.viewer().eye();
    state_.eye_now = state_.eye_next = glm::dvec3(eye[0], eye[1], eye[2]);
  }

  // Draws `projector` with `lights` (all: the full render) through its model.
  Drawn draw(const config::Projector& projector, const master::LightShare* share) {
    const config::Screen& screen = config_.installation.screens(0);
    auto geometry = config::projector_geometry(projector);
    EXPECT_TRUE(geometry);
    auto view = render::ProjectorView::make(screen, geometry.value(), render::RenderMethod::single_pass);
    EXPECT_TRUE(view);
    auto renderer = render::SceneRenderer::create(scene_, view.value().render_width(), view.value().render_height());
    EXPECT_TRUE(renderer);
    render::OutputStage stage = view.value().output_stage({});
    auto model = optics::ProjectorModel::from_config(projector);
    EXPECT_TRUE(model);
    stage.projector = model.value();
    EXPECT_TRUE(renderer.value()->set_output(stage));
    render::LightTerms terms;
    if (share != nullptr) {
      renderer.value()->set_lights(share->lights);
      terms = {share->ambient, share->ambient};
    }
    const auto& viewer = config_.installation.viewer();
    auto frustum = view.value().frustum(state_.eye_now, viewer.near(), viewer.far());
    EXPECT_TRUE(frustum);
    renderer.value()->draw(state_, 0.0, state_.eye_now, frustum.value(), terms);
    return {renderer.value()->read_rendered(), renderer.value()->read_linear()};
  }

  std::unique_ptr<render::GlContext> context_;
  config::LoadedConfig config_;
  scene::SceneDefinition scene_;
  scene::SceneState state_;
};

TEST_F(StackedLighting, TheOpticalSumIsTheFullRender) {
  const auto& installation = config_.installation;
  const auto shares = master::listed_shares(installation, scene_.lights.size());
  ASSERT_EQ(shares.size(), 3u);
  config::Projector single = installation.projectors(0);
  single.clear_response();
  single.set_black_level(0.0);
  single.set_brightness(1.0);
  const Drawn full = draw(single, nullptr);

  image::FloatImage sum(full.rendered.width, full.rendered.height, 4);
  image::FloatImage emitted_sum(full.rendered.width, full.rendered.height, 4);
  double black = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Drawn share = draw(installation.projectors(i), &shares.at(static_cast<std::size_t>(i)));
    for (std::size_t k = 0; k < sum.pixels.size(); ++k) {
      sum.pixels[k] += share.rendered.pixels[k];
      emitted_sum.pixels[k] += share.emitted.pixels[k];
    }
    black += optics::ProjectorModel::from_config(installation.projectors(i)).value().black();
  }
  // Before quantization: the sum of the shares is the full render.
  double worst = 0.0;
  double brightest = 0.0;
  for (std::size_t k = 0; k < sum.pixels.size(); ++k) {
    if (k % 4 == 3) continue;
    worst = std::max(worst, static_cast<double>(std::abs(sum.pixels[k] - full.rendered.pixels[k])));
    brightest = std::max(brightest, static_cast<double>(full.rendered.pixels[k]));
  }
  std::cout << "optical sum before quantization: max abs error " << worst << " (brightest value " << brightest << ")\n";
  EXPECT_LE(worst, 1e-3);
  EXPECT_GT(brightest, 0.3) << "the scene should be lit";

  // After each projector's 8-bit signal: the emitted sum less the group's black
  // is the full render to within the projectors' steps (where nothing clips).
  double emitted_worst = 0.0;
  for (std::size_t k = 0; k < sum.pixels.size(); ++k) {
    if (k % 4 == 3 || full.rendered.pixels[k] > 0.6f) continue;  // away from what clips
    emitted_worst =
        std::max(emitted_worst, std::abs(emitted_sum.pixels[k] - black - static_cast<double>(full.rendered.pixels[k])));
  }
  std::cout << "emitted sum − black (" << black << ") vs full render: max abs error " << emitted_worst << "\n";
  EXPECT_LE(emitted_worst, 0.02);
}

// The paper's intensity-resolution claim: along a smooth gradient of the wall,
// three stacked 8-bit projectors show more distinct light levels than one.
TEST_F(StackedLighting, ThreeProjectorsShowMoreLevelsThanOne) {
  const auto& installation = config_.installation;
  const auto shares = master::listed_shares(installation, scene_.lights.size());
  config::Projector plain = installation.projectors(0);
  plain.clear_response();
  plain.set_black_level(0.0);
  const Drawn one = draw(plain, nullptr);
  std::vector<Drawn> three;
  for (int i = 0; i < 3; ++i)
    three.push_back(draw(installation.projectors(i), &shares.at(static_cast<std::size_t>(i))));

  // A row of the wall above the statue, across the whole image: green channel.
  const int y = one.emitted.height / 10;
  std::set<float> single_levels;
  std::set<float> stacked_levels;
  for (int x = 0; x < one.emitted.width; ++x) {
    single_levels.insert(one.emitted.at(x, y, 1));
    float sum = 0.0f;
    for (const Drawn& d : three) sum += d.emitted.at(x, y, 1);
    stacked_levels.insert(sum);
  }
  std::cout << "distinct levels along row " << y << ": one projector " << single_levels.size() << ", three stacked "
            << stacked_levels.size() << "\n";
  EXPECT_GT(stacked_levels.size(), single_levels.size() * 3 / 2);
}

}  // namespace
}  // namespace optique
