// Colour fields drawn (render/projector_pipeline.h, draw_frame): on a single-chip
// DLP projector each channel shows the scene at the moment its field is on
// screen (Lancelle, Voß & Fellner). configs/dlp-120hz.json: the white square of
// `moving-square` crossing the wall at 3 m/s, B R G at −0.2, 0, +0.32 of the
// 1/120 s frame.

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <iterator>

#include "config/color_fields.h"
#include "config/job.h"
#include "geometry/homography.h"
#include "gl_installation.h"
#include "master/run/scene_authority.h"
#include "render/projector_pipeline.h"
#include "scene/builtin.h"

namespace optique {
namespace {

const std::string kConfig = std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-120hz.json";
constexpr int kFine = 4;  // edges measured on a 4×4-supersampled projector: to 1/8 px
// Frame 60 at 120 Hz: the square is in the middle of its crossing.
constexpr std::uint64_t kFrame = 60;

class FieldRendering : public ::testing::Test {
 protected:
  void SetUp() override {
    auto opened = testing::open_gl_installation(kConfig);
    ASSERT_TRUE(opened) << opened.error();
    gl_ = std::move(opened).value();
  }

  // The scene as the master sends frame k.
  [[nodiscard]] scene::SceneState state_at(std::uint64_t frame) const {
    const master::SceneAuthority authority(scene_.objects, installation_.viewer, installation_.master.frame_rate);
    return authority.state_at_frame(frame);
  }

  // The light rendered for the frame by `job`'s pipeline, as its node draws it.
  image::FloatImage drawn(const config::ProjectorJob& job, const scene::SceneState& state, bool fields = true) {
    auto pipeline = render::ProjectorPipeline::make(job, scene_);
    EXPECT_TRUE(pipeline) << (pipeline ? "" : pipeline.error());
    if (!pipeline) return {};
    const auto result = fields ? pipeline.value()->draw_frame(state) : pipeline.value()->draw(state);
    EXPECT_TRUE(result) << (result ? "" : result.error());
    return pipeline.value()->renderer().read_rendered();
  }

  // Where the square's left and right edges are, in the job's projector pixels,
  // `fraction` of a frame after frame k's display time: its pose from the scene
  // (0.2 m wide, 0.2 m behind the wall), seen from the eye onto the wall, through
  // the projector's homography.
  [[nodiscard]] std::pair<double, double> square_edges(const config::ProjectorJob& job, double fraction) const {
    const double t = (static_cast<double>(kFrame) + fraction) / installation_.master.frame_rate;
    const scene::Pose pose = scene_.objects.front().pose_at(t);
    const glm::dvec3 eye = installation_.viewer.eye_at(t);
    const auto on_wall = [&](double x) {
      const glm::dvec3 p(x, pose.position.y, pose.position.z);
      const glm::dvec3 hit = eye + (p - eye) * (eye.z / (eye.z - p.z));  // the wall is z = 0
      const config::Screen& s = job.screen();
      return geometry::apply(job.self().homography, {hit.x - s.origin.x, hit.y - s.origin.y}).x;
    };
    const double half = 0.5 * pose.scale.x;
    return {on_wall(pose.position.x - half), on_wall(pose.position.x + half)};
  }

  // The row through the square's middle, in the job's projector pixels.
  [[nodiscard]] int middle_row(const config::ProjectorJob& job) const {
    const double t = static_cast<double>(kFrame) / installation_.master.frame_rate;
    const config::Screen& s = job.screen();
    const double y = scene_.objects.front().pose_at(t).position.y;  // the eye is level with it
    return static_cast<int>(std::floor(geometry::apply(job.self().homography, {s.width / 2.0, y - s.origin.y}).y));
  }

  testing::GlInstallation gl_;
  const config::Installation& installation_ = gl_.config.installation;
  const scene::SceneDefinition& scene_ = gl_.scene;
};

// A channel's edges along `row`: the first and last pixel it lights (sampled at
// pixel centres, so each is within half a pixel of the true edge).
std::pair<double, double> lit_span(const image::FloatImage& image, int row, int channel) {
  int first = -1;
  int last = -1;
  for (int x = 0; x < image.width; ++x) {
    if (image.at(x, row, channel) < 0.5f) continue;
    if (first < 0) first = x;
    last = x;
  }
  return {first, last + 1.0};  // pixel boundaries
}

// The worst distance, in the projector's own pixels, between a channel's edge and
// where the square is when that channel's field is on screen.
double worst_edge_error(const image::FloatImage& fine_image, const std::vector<config::ColorField>& fields,
                        const std::function<std::pair<double, double>(double)>& edges_at, int row) {
  double worst = 0.0;
  for (const config::ColorField& field : fields) {
    const int channel = static_cast<int>(field.channel);
    const auto [left, right] = lit_span(fine_image, row, channel);
    const auto [want_left, want_right] = edges_at(field.offset);
    worst = std::max({worst, std::abs(left - want_left) / kFine, std::abs(right - want_right) / kFine});
  }
  return worst;
}

TEST_F(FieldRendering, EachChannelShowsTheSquareWhereItIsDuringItsField) {
  const config::ProjectorJob job = config::job_for(installation_, 0);
  const config::ProjectorJob fine = config::supersampled(job, kFine);
  const auto& fields = job.self().color_fields.fields;
  ASSERT_EQ(fields.size(), 3u);
  const scene::SceneState state = state_at(kFrame);
  const int row = middle_row(fine);
  const auto edges_at = [&](double fraction) { return square_edges(fine, fraction); };

  // The fields are apart by the square's motion: B 0.2 and G 0.32 of a frame from R.
  const double px_per_frame = (square_edges(job, 1.0).first - square_edges(job, 0.0).first);
  EXPECT_GT(px_per_frame, 3.0) << "the square must move far enough for the fields to part";

  const image::FloatImage per_field = drawn(fine, state);
  const double error = worst_edge_error(per_field, fields, edges_at, row);
  EXPECT_LE(error, 0.25) << "px; the square moves " << px_per_frame << " px per frame";
  std::cout << "per-field: worst channel edge " << error << " px from where the square is during its field ("
            << px_per_frame << " px per frame)\n";

  // Negative control: every channel drawn at the display time (method off), as a
  // projector without fields would. Blue is then 0.2 of a frame, green 0.32, off.
  const image::FloatImage plain = drawn(fine, state, false);
  const double plain_error = worst_edge_error(plain, fields, edges_at, row);
  EXPECT_GT(plain_error, 0.3 * px_per_frame - 0.25) << "the check must see a frame drawn at one moment";
  std::cout << "all colours at the display time: worst channel edge " << plain_error << " px off\n";
}

TEST_F(FieldRendering, WithoutMotionTheFieldsAreThePlainRender) {
  const config::ProjectorJob job = config::job_for(installation_, 0);
  scene::SceneState still = state_at(kFrame);
  for (auto& [id, object] : still.objects) object.next = object.now;
  still.eye_next = still.eye_now;
  const image::FloatImage per_field = drawn(job, still);
  const image::FloatImage plain = drawn(job, still, false);
  ASSERT_EQ(per_field.pixels.size(), plain.pixels.size());
  float worst = 0.0f;
  for (std::size_t i = 0; i < plain.pixels.size(); ++i) {
    worst = std::max(worst, std::abs(per_field.pixels[i] - plain.pixels[i]));
  }
  EXPECT_LE(worst, 1e-6f);
  float lit = 0.0f;
  for (const float v : plain.pixels) lit = std::max(lit, v);
  EXPECT_GT(lit, 0.5f) << "the square is in the picture";
}

// cubes-backdrop: moving cubes before a still wall. Seen from one place, the wall
// is drawn once for all fields; nudging the eye between the frame's two poses
// by a nanometre makes every field draw everything. The two must agree.
TEST_F(FieldRendering, StillObjectsDrawnOnceAreAsDrawnInEveryField) {
  const config::ProjectorJob job = config::job_for(installation_, 0);
  auto backdrop = scene::builtin_scene("cubes-backdrop");
  ASSERT_TRUE(backdrop) << backdrop.error();
  const master::SceneAuthority authority(backdrop.value().objects, installation_.viewer,
                                         installation_.master.frame_rate);
  const scene::SceneState once = authority.state_at_frame(kFrame);
  scene::SceneState every = once;
  every.eye_next.x += 1e-9;
  ASSERT_EQ(once.eye_now, once.eye_next) << "the viewer of dlp-120hz stands still";
  const auto draw = [&](const scene::SceneState& state) {
    auto pipeline = render::ProjectorPipeline::make(job, backdrop.value());
    EXPECT_TRUE(pipeline) << (pipeline ? "" : pipeline.error());
    if (!pipeline) return image::FloatImage{};
    EXPECT_TRUE(pipeline.value()->draw_frame(state));
    return pipeline.value()->renderer().read_rendered();
  };
  const image::FloatImage a = draw(once);
  const image::FloatImage b = draw(every);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  float worst = 0.0f;
  int differing = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const float d = std::abs(a.pixels[i] - b.pixels[i]);
    worst = std::max(worst, d);
    differing += d > 1e-6f ? 1 : 0;
  }
  std::cout << "still objects once against every field: worst " << worst << ", " << differing
            << " channel values differ by more than 1e-6\n";
  EXPECT_LE(worst, 1e-5f);
}

// The stereo projector used as mono: six fields in two images per frame, each
// image's channels where the square is during their fields, both drawn by one
// draw_frame (the second after the first was read, as a node captures them).
TEST_F(FieldRendering, EachOfTwoImagesShowsItsOwnThreeFields) {
  config::ProjectorJob job = config::job_for(installation_, 0);
  schema::ColorFields preset;
  preset.set_preset("dlp-stereo-as-mono");
  std::vector<config::Problem> problems;
  job.installation.projectors[job.projector].color_fields = config::parse_color_fields(preset, "test", problems);
  ASSERT_TRUE(problems.empty());
  const config::ProjectorJob fine = config::supersampled(job, kFine);
  const auto& fields = fine.self().color_fields.fields;
  ASSERT_EQ(fields.size(), 6u);
  const int row = middle_row(fine);
  const auto edges_at = [&](double fraction) { return square_edges(fine, fraction); };

  auto pipeline = render::ProjectorPipeline::make(fine, scene_);
  ASSERT_TRUE(pipeline) << pipeline.error();
  ASSERT_EQ(pipeline.value()->images(), 2);
  std::vector<image::FloatImage> images;
  std::vector<image::ByteImage> signals;  // as sent to the projector
  const auto drawn = pipeline.value()->draw_frame(state_at(kFrame), [&](int image) {
    EXPECT_EQ(image, static_cast<int>(images.size()));
    images.push_back(pipeline.value()->renderer().read_rendered());
    signals.push_back(pipeline.value()->renderer().output().read_encoded());
  });
  ASSERT_TRUE(drawn) << drawn.error();
  ASSERT_EQ(images.size(), 2u);
  // What a window would show of each image, once both are drawn: the first one
  // held aside, the second in the output.
  for (int image = 0; image < 2; ++image) {
    const image::ByteImage& want = signals[static_cast<std::size_t>(image)];
    image::ByteImage shown(want.width, want.height, 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, pipeline.value()->image_framebuffer(image));
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, shown.width, shown.height, GL_RGBA, GL_UNSIGNED_BYTE, shown.pixels.data());
    image::flip_rows(shown);
    EXPECT_TRUE(shown.pixels == want.pixels) << "image " << image << " is not what is shown for it";
  }
  EXPECT_FALSE(signals[0].pixels == signals[1].pixels) << "the square moved between the images";
  for (int image = 0; image < 2; ++image) {
    std::vector<config::ColorField> own;
    std::copy_if(fields.begin(), fields.end(), std::back_inserter(own),
                 [&](const config::ColorField& f) { return f.image == image; });
    ASSERT_EQ(own.size(), 3u);
    const double error = worst_edge_error(images[static_cast<std::size_t>(image)], own, edges_at, row);
    std::cout << "image " << image << ": worst channel edge " << error << " px from its field's moment\n";
    EXPECT_LE(error, 0.25) << "image " << image;
  }
  // Negative control: the second image's fields checked against the first's
  // image: half a frame off.
  std::vector<config::ColorField> second(fields.begin() + 3, fields.end());
  EXPECT_GT(worst_edge_error(images[0], second, edges_at, row), 1.0);
}

}  // namespace
}  // namespace optique
