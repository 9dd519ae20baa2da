#include "image/edges.h"

#include <gtest/gtest.h>

#include <cmath>

namespace optique::image {
namespace {

// A bright disc on a dark ground, its edge anti-aliased by coverage (16×16
// samples per pixel), centred at (cx, cy).
FloatImage disc(double cx, double cy, double radius, int size = 64) {
  FloatImage image(size, size, 4);
  constexpr int kSamples = 16;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      int inside = 0;
      for (int j = 0; j < kSamples; ++j) {
        for (int i = 0; i < kSamples; ++i) {
          const double px = x + (i + 0.5) / kSamples;
          const double py = y + (j + 0.5) / kSamples;
          if (std::hypot(px - cx, py - cy) < radius) ++inside;
        }
      }
      const float v = 0.05f + 0.8f * static_cast<float>(inside) / (kSamples * kSamples);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = v;
      image.at(x, y, 3) = 1.0f;
    }
  }
  return image;
}

TEST(EdgeShifts, IdenticalImagesHaveNoShift) {
  const FloatImage a = disc(32.3, 31.7, 15.0);
  const EdgeShifts shifts = edge_shifts(a, a, {});
  EXPECT_GT(shifts.edges, 20u);
  EXPECT_EQ(shifts.max_abs_px, 0.0);
  EXPECT_EQ(shifts.max_widening_px, 0.0);
}

TEST(EdgeShifts, MeasuresASubPixelMove) {
  const FloatImage a = disc(32.0, 32.0, 15.0);
  const FloatImage b = disc(32.4, 32.0, 15.0);  // 0.4 px to the right
  const EdgeShifts shifts = edge_shifts(a, b, {});
  ASSERT_GT(shifts.edges, 20u);
  // Left and right edges move 0.4 px, top and bottom barely.
  EXPECT_NEAR(shifts.max_abs_px, 0.4, 0.06);
}

TEST(EdgeShifts, ADoubledEdgeShowsAsAShift) {
  // Two copies of the disc, each at half strength, 1.5 px apart: what a viewer
  // sees where two misregistered projectors overlap.
  const FloatImage a = disc(32.0, 32.0, 15.0);
  const FloatImage left = disc(31.25, 32.0, 15.0);
  const FloatImage right = disc(32.75, 32.0, 15.0);
  FloatImage doubled = a;
  for (std::size_t i = 0; i < doubled.pixels.size(); ++i) doubled.pixels[i] = 0.5f * (left.pixels[i] + right.pixels[i]);
  FloatImage moved = right;
  const EdgeShifts symmetric = edge_shifts(a, doubled, {});
  const EdgeShifts shifted = edge_shifts(a, moved, {});
  // A symmetric double edge keeps its centroid, but not its width.
  EXPECT_LT(symmetric.max_abs_px, 0.3);
  EXPECT_GT(symmetric.max_widening_px, 0.4);
  EXPECT_GT(shifted.max_abs_px, 0.6);
  EXPECT_LT(shifted.max_widening_px, 0.25);  // sampling moves within a pixel
}

TEST(EdgeShifts, OnlyWhereAsked) {
  const FloatImage a = disc(32.0, 32.0, 15.0);
  const FloatImage b = disc(32.4, 32.0, 15.0);
  EdgeOptions options;
  options.where = [](int x, int) { return x > 60; };  // no edge there
  EXPECT_EQ(edge_shifts(a, b, options).edges, 0u);
}

}  // namespace
}  // namespace optique::image
