// The eye that follows motion on a screen: common/optics/perceive.h, on synthetic
// screen images with answers known in closed form.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "optics/perceive.h"

namespace optique::optics {
namespace {

constexpr int kWidth = 200;
constexpr int kHeight = 20;
constexpr double kPeriod = 1.0 / 120.0;  // seconds per frame

// A white bar [left, left + 20) px wide, the full height, on black.
image::FloatImage bar_at(double left) {
  image::FloatImage image(kWidth, kHeight, 4);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      // Coverage of the pixel by the bar, so sub-pixel positions are exact.
      const double cover = std::clamp(std::min(x + 1.0, left + 20.0) - std::max(x + 0.0, left), 0.0, 1.0);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(cover);
      image.at(x, y, 3) = 1.0f;
    }
  }
  return image;
}

// The centre of mass of one channel along the middle row.
double centre_of(const image::FloatImage& image, int channel) {
  double sum = 0.0;
  double moment = 0.0;
  for (int x = 0; x < image.width; ++x) {
    const double v = image.at(x, kHeight / 2, channel);
    sum += v;
    moment += v * (x + 0.5);
  }
  return moment / sum;
}

TEST(Perceive, AStillImageSeenByAStillEyeIsTheImage) {
  const image::FloatImage bar = bar_at(50.3);
  // Two frames, each shown as three colour fields of a third of the frame.
  std::vector<Emission> emissions;
  for (int frame = 0; frame < 2; ++frame) {
    for (int c = 0; c < 3; ++c) {
      Emission e{&bar, c == 0, c == 1, c == 2};
      e.start = (frame + c / 3.0) * kPeriod;
      e.end = (frame + (c + 1) / 3.0) * kPeriod;
      e.on_fraction = 1.0 / 3.0;
      emissions.push_back(e);
    }
  }
  const image::FloatImage seen = perceive(emissions, kWidth, kHeight, {kPeriod, 2.0 * kPeriod, {0.0, 0.0}});
  float worst = 0.0f;
  for (std::size_t i = 0; i < seen.pixels.size(); ++i)
    worst = std::max(worst, std::abs(seen.pixels[i] - bar.pixels[i]));
  EXPECT_LE(worst, 1e-6f);
  EXPECT_EQ(fringe_width(seen, 0, 0, kWidth, kHeight), 0.0);
}

// A bar moving at `speed` px/s on a projector with three fields: R at −⅓, G at 0,
// B at +⅓ of the frame, each a third long. `per_field`: each channel drawn where
// the bar is during its field; otherwise all at the frame's display time. The
// exposure is centred on frame `centre_frame`'s display time.
image::FloatImage tracked(double speed, bool per_field, int centre_frame = 0) {
  const double offsets[3] = {-1.0 / 3.0, 0.0, 1.0 / 3.0};
  std::vector<image::FloatImage> images;
  images.reserve(12);
  std::vector<Emission> emissions;
  for (int frame = -2; frame <= 2; ++frame) {
    const double shown = frame * kPeriod;  // display time
    for (int c = 0; c < 3; ++c) {
      const double drawn_at = per_field ? shown + offsets[c] * kPeriod : shown;
      images.push_back(bar_at(90.0 + speed * drawn_at));
    }
  }
  int i = 0;
  for (int frame = -2; frame <= 2; ++frame) {
    for (int c = 0; c < 3; ++c, ++i) {
      Emission e{&images[static_cast<std::size_t>(i)], c == 0, c == 1, c == 2};
      const double middle = (frame + offsets[c]) * kPeriod;
      e.start = middle - kPeriod / 6.0;
      e.end = middle + kPeriod / 6.0;
      e.on_fraction = 1.0 / 3.0;
      emissions.push_back(e);
    }
  }
  // One 60 Hz frame of exposure.
  return perceive(emissions, kWidth, kHeight, {centre_frame * kPeriod, 2.0 * kPeriod, {speed, 0.0}});
}

TEST(Perceive, ATrackedBarShowsFringesOfSpeedTimesFieldSpacing) {
  const double speed = 6.0 / kPeriod;  // 6 px per frame
  const image::FloatImage conventional = tracked(speed, false);
  // Each channel lands where the eye was when its field showed: −⅓ and +⅓ of a
  // frame apart, 2 px at 6 px per frame, the other way than the bar moves.
  EXPECT_NEAR(centre_of(conventional, 0) - centre_of(conventional, 1), 2.0, 1e-3);
  EXPECT_NEAR(centre_of(conventional, 2) - centre_of(conventional, 1), -2.0, 1e-3);
  // At each edge, R's and B's halfway points 4 px apart (⅔ of a frame).
  EXPECT_NEAR(fringe_width(conventional, 0, 0, kWidth, kHeight), 4.0, 1e-3);

  const image::FloatImage fields = tracked(speed, true);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre_of(fields, c), centre_of(fields, 1), 1e-3) << c;
  EXPECT_LT(fringe_width(fields, 0, 0, kWidth, kHeight), 1e-3);
  // Drawn per field and tracked, the bar is sharp: its edge within a pixel.
  EXPECT_GT(fields.at(100, kHeight / 2, 0), 0.99f);
  EXPECT_LT(fields.at(88, kHeight / 2, 0), 0.01f);
}

// The retina is aligned with the screen at the exposure's centre: the tracked
// bar is seen where it is then (its middle at 100 px at frame 0, 6 px on a
// frame later), not where it was when the exposure opened.
TEST(Perceive, TheTrackedBarIsSeenWhereItIsAtTheExposuresCentre) {
  const double speed = 6.0 / kPeriod;
  EXPECT_NEAR(centre_of(tracked(speed, true, 0), 1), 100.0, 1e-3);
  EXPECT_NEAR(centre_of(tracked(speed, true, 1), 1), 106.0, 1e-3);
}

}  // namespace
}  // namespace optique::optics
