#include "optics/defocus.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace optique::optics {
namespace {

const CocRange kRange{1.0, 10.0};

image::FloatImage impulse(int size, int x, int y, int channels = 1) {
  image::FloatImage image(size, size, channels);
  for (int c = 0; c < channels; ++c) image.at(x, y, c) = 1.0f;
  return image;
}

image::FloatImage constant_map(int width, int height, float radius) {
  image::FloatImage map(width, height, 1);
  std::fill(map.pixels.begin(), map.pixels.end(), radius);
  return map;
}

image::FloatImage random_image(int width, int height, int channels, unsigned seed) {
  image::FloatImage image(width, height, channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(0.0f, 1.0f);
  for (float& p : image.pixels) p = value(rng);
  return image;
}

double channel_sum(const image::FloatImage& image, int c) {
  double sum = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) sum += image.at(x, y, c);
  }
  return sum;
}

double max_abs_difference(const image::FloatImage& a, const image::FloatImage& b) {
  EXPECT_EQ(a.pixels.size(), b.pixels.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    worst = std::max(worst, std::abs(static_cast<double>(a.pixels[i]) - b.pixels[i]));
  }
  return worst;
}

// z from `from` to `to`, log-spaced.
std::vector<double> log_spaced(double from, double to, int count) {
  std::vector<double> z;
  for (int i = 0; i < count; ++i) z.push_back(from * std::pow(to / from, static_cast<double>(i) / (count - 1)));
  return z;
}

TEST(RelativeCoc, ZeroAtFocusOneAcrossTheRange) {
  for (double b : {1.0, 2.0, 3.7, 10.0}) EXPECT_EQ(relative_coc(b, b, kRange), 0.0) << b;
  EXPECT_NEAR(relative_coc(kRange.near, kRange.far, kRange), 1.0, 1e-12);
  EXPECT_NEAR(relative_coc(kRange.far, kRange.near, kRange), 1.0, 1e-12);
  // Halfway in 1/z between 1 and 10 is z = 2/1.1.
  EXPECT_NEAR(relative_coc(2.0 / 1.1, kRange.far, kRange), 0.5, 1e-12);
}

TEST(RelativeCoc, ClampsDepthAndFocus) {
  EXPECT_EQ(relative_coc(0.2, 5.0, kRange), relative_coc(kRange.near, 5.0, kRange));
  EXPECT_EQ(relative_coc(1e6, 5.0, kRange), relative_coc(kRange.far, 5.0, kRange));
  EXPECT_EQ(relative_coc(3.0, 0.01, kRange), relative_coc(3.0, kRange.near, kRange));
  EXPECT_EQ(relative_coc(3.0, 50.0, kRange), relative_coc(3.0, kRange.far, kRange));
  EXPECT_NEAR(relative_coc(0.01, 1e9, kRange), 1.0, 1e-12);
  EXPECT_EQ(relative_coc(0.5, 0.7, kRange), 0.0);  // both clamp to near
}

TEST(RelativeCoc, GrowsAwayFromFocusOnBothSides) {
  const double b = 3.0;
  const std::vector<double> depths = log_spaced(kRange.near, kRange.far, 400);
  double previous = -1.0;
  bool reached_focus = false;
  for (double z : depths) {
    const double c = relative_coc(z, b, kRange);
    EXPECT_GE(c, 0.0);
    EXPECT_LE(c, 1.0);
    if (z <= b) {
      if (previous >= 0.0) {
        EXPECT_LT(c, previous) << z;
      }
    } else {
      if (reached_focus) {
        EXPECT_GT(c, previous) << z;
      }
      reached_focus = true;
    }
    previous = c;
  }
}

TEST(WindowDepth, ZeroAtNearOneAtFarIncreasing) {
  EXPECT_NEAR(window_depth(0.05, 0.05, 100.0), 0.0, 1e-15);
  EXPECT_NEAR(window_depth(100.0, 0.05, 100.0), 1.0, 1e-15);
  double previous = -1.0;
  for (double z : log_spaced(0.05, 100.0, 100)) {
    const double d = window_depth(z, 0.05, 100.0);
    EXPECT_GT(d, previous);
    previous = d;
  }
}

// The mapping's four numbers evaluated in double: the algebra of the window-depth form.
double coc_in_double(double window, const CocFromWindowDepth& mapping) {
  return mapping.k * std::abs(std::clamp(window, mapping.lo, mapping.hi) - mapping.focal);
}

TEST(WindowDepth, ShaderFormAgreesWithExactForm) {
  const double n = 0.05;
  const double f = 100.0;
  double worst_double = 0.0;
  double worst_float = 0.0;
  for (double b : {0.5, 1.0, 1.5, 2.0, 3.0, 5.0, 7.5, 10.0, 40.0}) {
    const CocFromWindowDepth mapping = coc_from_window_depth(b, kRange, n, f);
    // In float the window depth near 1 is only known to 2^-25 and so is b'; times k (≈ 22 here) that is
    // ~1e-6, which no shader can beat with a float depth: the bound is a few float steps of z' times k.
    const double float_bound = mapping.k * std::pow(2.0, -23);
    for (double z : log_spaced(n, f, 2000)) {
      const double window = window_depth(z, n, f);
      const double exact = relative_coc(z, b, kRange);
      const double in_double = coc_in_double(window, mapping);
      const double in_float = relative_coc(static_cast<float>(window), mapping);
      worst_double = std::max(worst_double, std::abs(in_double - exact));
      worst_float = std::max(worst_float, std::abs(in_float - exact));
      ASSERT_NEAR(in_double, exact, 1e-6) << "b " << b << " z " << z;
      ASSERT_NEAR(in_float, exact, float_bound) << "b " << b << " z " << z;
    }
  }
  std::printf(
      "window-depth form vs exact (near 0.05, far 100, range 1..10): max |dc_r| %.3g in double, %.3g in float\n",
      worst_double, worst_float);
}

TEST(WindowDepth, QuantizedTo24BitsStaysAccurate) {
  const double n = 0.01;
  const double f = 100.0;
  const CocRange range{n, f};
  const double levels = std::pow(2.0, 24) - 1.0;
  double worst = 0.0;
  for (double b : {0.01, 0.1, 1.0, 10.0, 100.0}) {
    const CocFromWindowDepth mapping = coc_from_window_depth(b, range, n, f);
    for (double z : log_spaced(n, f, 5000)) {
      const double stored = std::round(window_depth(z, n, f) * levels) / levels;
      worst = std::max(worst, std::abs(relative_coc(static_cast<float>(stored), mapping) - relative_coc(z, b, range)));
    }
  }
  std::printf("24-bit window depth (near 0.01, far 100, range = frustum): max |dc_r| = %.3g\n", worst);
  EXPECT_LT(worst, 1e-4);
}

TEST(WindowDepth, ShaderFormClampsAndCapsAtOne) {
  const CocFromWindowDepth mapping = coc_from_window_depth(3.0, kRange, 0.05, 100.0);
  EXPECT_EQ(relative_coc(0.0f, mapping), relative_coc(static_cast<float>(mapping.lo), mapping));
  EXPECT_EQ(relative_coc(1.0f, mapping), relative_coc(static_cast<float>(mapping.hi), mapping));
  const CocFromWindowDepth far_focus = coc_from_window_depth(10.0, kRange, 0.05, 100.0);
  EXPECT_LE(relative_coc(0.0f, far_focus), 1.0);
  EXPECT_NEAR(relative_coc(0.0f, far_focus), 1.0, 1e-5);
}

TEST(DiscBlur, RadiusZeroIsIdentity) {
  const image::FloatImage image = random_image(23, 17, 4, 1);
  EXPECT_EQ(disc_blur(image, 0.0).pixels, image.pixels);
  EXPECT_EQ(disc_blur(image, 0.3).pixels, image.pixels);
  EXPECT_LT(max_abs_difference(scatter_defocus(image, constant_map(23, 17, 0.0f)), image), 1e-7);
}

TEST(DiscBlur, ConservesEnergyOfInteriorImpulse) {
  for (double r : {0.7, 1.0, 2.5, 5.0, 7.3, 12.0}) {
    const image::FloatImage blurred = disc_blur(impulse(41, 20, 20, 3), r);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(channel_sum(blurred, c), 1.0, 1e-5) << r;
    const image::FloatImage scattered =
        scatter_defocus(impulse(41, 20, 20), constant_map(41, 41, static_cast<float>(r)));
    EXPECT_NEAR(channel_sum(scattered, 0), 1.0, 1e-5) << r;
  }
}

TEST(DiscBlur, LightOutsideTheImageIsLost) {
  // Radius 1.5 is the 3 × 3 disc; from a corner pixel 4 of its 9 pixels are inside.
  const image::FloatImage blurred = disc_blur(impulse(9, 0, 0), 1.5);
  EXPECT_NEAR(channel_sum(blurred, 0), 4.0 / 9.0, 1e-6);
  EXPECT_NEAR(blurred.at(1, 1, 0), 1.0 / 9.0, 1e-7);
}

TEST(DiscBlur, ImpulseMakesADiscOfTheRadius) {
  const int centre = 20;
  const image::FloatImage blurred = disc_blur(impulse(41, centre, centre), 5.0);
  double inside = 0.0;
  for (int y = 0; y < blurred.height; ++y) {
    for (int x = 0; x < blurred.width; ++x) {
      const double d = std::hypot(x - centre, y - centre);
      const double v = blurred.at(x, y, 0);
      EXPECT_GE(v, -1e-12) << x << "," << y;
      if (d <= 5.0) {
        EXPECT_GT(v, 1e-4) << x << "," << y;
        inside += v;
      }
      if (d > 6.0) {
        EXPECT_LT(std::abs(v), 1e-12) << x << "," << y;
      }
    }
  }
  EXPECT_GT(inside, 0.8);  // nearly all light within the radius, the rest in the pixels just outside
  // Even spread: the centre and a pixel 3 px away get the same light.
  EXPECT_NEAR(blurred.at(centre, centre, 0), blurred.at(centre + 3, centre, 0), 1e-9);
}

TEST(DiscBlur, IsSymmetric) {
  const int c = 15;
  for (double r : {2.2, 6.6, 9.0}) {
    const image::FloatImage blurred = disc_blur(impulse(31, c, c), r);
    for (int dy = -c; dy <= c; ++dy) {
      for (int dx = -c; dx <= c; ++dx) {
        const float v = blurred.at(c + dx, c + dy, 0);
        EXPECT_NEAR(v, blurred.at(c - dx, c + dy, 0), 1e-9);
        EXPECT_NEAR(v, blurred.at(c + dx, c - dy, 0), 1e-9);
        EXPECT_NEAR(v, blurred.at(c + dy, c + dx, 0), 1e-9);
      }
    }
  }
}

TEST(DiscBlur, CopiesAlphaAndBlursTheOtherChannels) {
  image::FloatImage image = impulse(21, 10, 10, 4);
  image.at(3, 4, 3) = 0.25f;
  const image::FloatImage blurred = disc_blur(image, 4.0);
  for (int y = 0; y < 21; ++y) {
    for (int x = 0; x < 21; ++x) EXPECT_EQ(blurred.at(x, y, 3), image.at(x, y, 3));
  }
  EXPECT_LT(blurred.at(10, 10, 0), 0.1f);
  EXPECT_EQ(blurred.at(11, 10, 2), blurred.at(11, 10, 0));
}

TEST(ScatterDefocus, ConstantMapEqualsDiscBlur) {
  for (int channels : {1, 3, 4}) {
    const image::FloatImage image = random_image(37, 29, channels, 7 + channels);
    for (float r : {0.0f, 0.4f, 0.5f, 1.0f, 1.5f, 2.7f, 5.0f, 7.25f, 16.0f, 40.0f}) {
      const image::FloatImage blurred = disc_blur(image, r);
      const image::FloatImage scattered = scatter_defocus(image, constant_map(37, 29, r));
      EXPECT_LT(max_abs_difference(blurred, scattered), 1e-6) << channels << " channels, radius " << r;
    }
  }
}

TEST(ScatterDefocus, EachPixelUsesItsOwnRadius) {
  // Light adds, so the scatter of three impulses is the sum of each blurred by its own radius.
  const int size = 45;
  image::FloatImage image(size, size, 1);
  image::FloatImage radius(size, size, 1);
  const int xs[] = {10, 22, 33};
  const float radii[] = {0.0f, 3.4f, 8.0f};
  image::FloatImage expected(size, size, 1);
  for (int i = 0; i < 3; ++i) {
    image.at(xs[i], 20, 0) = 1.0f + i;
    for (int y = 0; y < size; ++y) radius.at(xs[i], y, 0) = radii[i];
    image::FloatImage alone(size, size, 1);
    alone.at(xs[i], 20, 0) = 1.0f + i;
    const image::FloatImage blurred = disc_blur(alone, radii[i]);
    for (std::size_t p = 0; p < expected.pixels.size(); ++p) expected.pixels[p] += blurred.pixels[p];
  }
  const image::FloatImage scattered = scatter_defocus(image, radius);
  EXPECT_LT(max_abs_difference(scattered, expected), 1e-6);
  EXPECT_NEAR(channel_sum(scattered, 0), 6.0, 1e-5);
}

TEST(ScatterDefocus, ContinuousInTheRadius) {
  const int size = 45;
  const image::FloatImage source = impulse(size, 22, 22);
  double worst = 0.0;
  // Steps of 0.01 from an offset of 0.005 straddle every knot of the discs (r = R + ½).
  for (int i = 0; i <= 1000; ++i) {
    const float r = 0.005f + 0.01f * i;
    const double step = max_abs_difference(scatter_defocus(source, constant_map(size, size, r)),
                                           scatter_defocus(source, constant_map(size, size, r + 0.01f)));
    worst = std::max(worst, step);
    EXPECT_LT(step, 1e-2) << "radius " << r;
  }
  std::printf("largest change of an impulse's image for a radius step of 0.01: %.3g\n", worst);
}

TEST(ScatterDefocus, NoNanForExtremeFiniteInput) {
  image::FloatImage image = random_image(19, 13, 4, 3);
  image.at(0, 0, 0) = 1e30f;
  image.at(5, 5, 1) = 0.0f;
  image::FloatImage radius(19, 13, 1);
  const float radii[] = {0.0f, 1e-30f, 0.5f, 3.0f, 4096.0f, 1e6f, 3.0e38f};
  for (std::size_t i = 0; i < radius.pixels.size(); ++i) radius.pixels[i] = radii[i % 7];
  const image::FloatImage scattered = scatter_defocus(image, radius);
  for (float v : scattered.pixels) EXPECT_FALSE(std::isnan(v));
  for (float v : disc_blur(image, 1e300).pixels) EXPECT_FALSE(std::isnan(v));
  EXPECT_TRUE(disc_blur(image::FloatImage(0, 0, 3), 4.0).empty());
}

TEST(ScatterDefocus, Timing) {
  // Not asserted: prints what the reference costs at the experiments' size.
  const image::FloatImage image = random_image(1280, 720, 4, 11);
  auto start = std::chrono::steady_clock::now();
  const image::FloatImage blurred = disc_blur(image, 16.0);
  const double blur_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  image::FloatImage radius(1280, 720, 1);
  for (int y = 0; y < 720; ++y) {
    for (int x = 0; x < 1280; ++x) radius.at(x, y, 0) = 16.0f * x / 1279.0f;
  }
  start = std::chrono::steady_clock::now();
  const image::FloatImage scattered = scatter_defocus(image, radius);
  const double scatter_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("1280x720x4: disc_blur radius 16 %.3f s; scatter_defocus radius 0..16 ramp %.3f s\n", blur_s, scatter_s);
  EXPECT_FALSE(blurred.empty());
  EXPECT_FALSE(scattered.empty());
}

}  // namespace
}  // namespace optique::optics
