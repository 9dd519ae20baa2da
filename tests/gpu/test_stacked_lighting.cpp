// The lighting split of configs/stacked-lighting-3.json drawn in-process: three
// projectors, each with its share of the 20 lights and its own response, black
// level and brightness, against one projector drawing everything (Majumder &
// Welch, "Computer Graphics Optique": the screen adds the light; m projectors show more levels).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "config/job.h"
#include "config/load.h"
#include "gl_installation.h"
#include "master/run/stacked_groups.h"
#include "optics/projector_model.h"
#include "render/projector_pipeline.h"

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
    auto opened = testing::open_gl_installation(kConfig);
    ASSERT_TRUE(opened) << opened.error();
    gl_ = std::move(opened).value();
    for (const auto& object : scene_.objects) {
      state_.objects[object.id] = {object.pose_at(1.0), object.pose_at(1.0)};
    }
    state_.eye_now = state_.eye_next = config_.installation.viewer.eye_at(0.0);
  }

  // Projector i's job, as its node gets it.
  config::ProjectorJob job(std::size_t i) const { return config::job_for(config_.installation, i); }

  // Draws the job's projector with its share of the lights (none: all of them,
  // the full render), through its pipeline as a node would.
  Drawn draw(const config::ProjectorJob& job, const master::LightShare* share) {
    auto pipeline = render::ProjectorPipeline::make(job, scene_);
    EXPECT_TRUE(pipeline) << (pipeline ? "" : pipeline.error());
    if (!pipeline) return {};
    if (share != nullptr) pipeline.value()->set_share(*share);
    const auto drawn = pipeline.value()->draw(state_);
    EXPECT_TRUE(drawn) << (drawn ? "" : drawn.error());
    return {pipeline.value()->renderer().read_rendered(), pipeline.value()->renderer().output().read_linear()};
  }

  testing::GlInstallation gl_;
  const config::LoadedConfig& config_ = gl_.config;
  scene::SceneDefinition& scene_ = gl_.scene;
  scene::SceneState state_;
};

TEST_F(StackedLighting, TheOpticalSumIsTheFullRender) {
  const auto& installation = config_.installation;
  const auto shares = master::listed_shares(installation, scene_.lights.size());
  ASSERT_EQ(shares.size(), 3u);
  // One plain projector (sRGB, no black, brightness 1) drawing every light.
  config::ProjectorJob single = job(0);
  single.installation.projectors[single.projector].response = {};
  single.installation.projectors[single.projector].content = {};
  const Drawn full = draw(single, nullptr);

  image::FloatImage sum(full.rendered.width, full.rendered.height, 4);
  image::FloatImage emitted_sum(full.rendered.width, full.rendered.height, 4);
  double black = 0.0;
  for (int i = 0; i < 3; ++i) {
    const Drawn share = draw(job(static_cast<std::size_t>(i)), &shares.at(static_cast<std::size_t>(i)));
    for (std::size_t k = 0; k < sum.pixels.size(); ++k) {
      sum.pixels[k] += share.rendered.pixels[k];
      emitted_sum.pixels[k] += share.emitted.pixels[k];
    }
    black += optics::ProjectorModel(installation.projectors[static_cast<std::size_t>(i)].response).black();
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
  // Float rounding only: 4.8e-7 measured on llvmpipe; a GPU that sums the
  // lights in another order or fuses the operations differs by a few ulps per
  // light (20 lights, values up to ~1), hence the margin.
  EXPECT_LE(worst, 1e-5);
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
  // One 8-bit sRGB projector without black, as bright as the first.
  config::ProjectorJob plain = job(0);
  config::Projector& one_projector = plain.installation.projectors[plain.projector];
  const double brightness = one_projector.response.brightness;
  one_projector.response = {};
  one_projector.response.brightness = brightness;
  one_projector.content = {};
  const Drawn one = draw(plain, nullptr);
  std::vector<Drawn> three;
  for (std::size_t i = 0; i < 3; ++i) three.push_back(draw(job(i), &shares.at(i)));

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
