// Image comparison (image/compare.h): PSNR per channel and the up-conversion
// paper's PSNR_Y from known errors, and its 4×4 block classes.

#include "image/compare.h"

#include <gtest/gtest.h>

#include <cmath>

namespace optique::image {
namespace {

FloatImage filled(int width, int height, float r, float g, float b) {
  FloatImage image(width, height, 4);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.at(x, y, 0) = r;
      image.at(x, y, 1) = g;
      image.at(x, y, 2) = b;
      image.at(x, y, 3) = 1.0f;
    }
  }
  return image;
}

TEST(Compare, PsnrYWeighsEachChannelsPsnr) {
  const FloatImage a = filled(8, 8, 0.5f, 0.5f, 0.5f);
  const FloatImage b = filled(8, 8, 0.6f, 0.51f, 0.4f);  // errors 0.1, 0.01, 0.1: 20, 40, 20 dB
  const auto c = compare(a, b);
  ASSERT_TRUE(c.ok()) << c.error();
  EXPECT_NEAR(c.value().psnr_r, 20.0, 1e-4);
  EXPECT_NEAR(c.value().psnr_g, 40.0, 1e-3);
  EXPECT_NEAR(c.value().psnr_y_weighted, 0.299 * 20.0 + 0.587 * 40.0 + 0.114 * 20.0, 1e-3);
  EXPECT_NEAR(c.value().max_abs_error, 0.1, 1e-6);
  EXPECT_TRUE(std::isinf(compare(a, a).value().psnr_y_weighted));
  EXPECT_FALSE(compare(a, filled(4, 8, 0, 0, 0)).ok());
}

TEST(Compare, BlockClassesCountEach4x4BlockOnce) {
  FloatImage a = filled(8, 4, 0.5f, 0.5f, 0.5f);  // two blocks
  FloatImage b = a;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int ch = 0; ch < 3; ++ch) b.at(x, y, ch) = 0.55f;  // the left block: 26 dB
    }
  }
  const auto classes = block_classes(a, b);
  ASSERT_TRUE(classes.ok()) << classes.error();
  EXPECT_DOUBLE_EQ(classes.value().share[0], 0.0);
  EXPECT_DOUBLE_EQ(classes.value().share[1], 0.5) << "26 dB is bad";
  EXPECT_DOUBLE_EQ(classes.value().share[3], 0.5) << "identical is better than good";
  EXPECT_NEAR(classes.value().worst_db, 20.0 * std::log10(1.0 / 0.05), 1e-3);
  EXPECT_FALSE(block_classes(a, filled(4, 4, 0, 0, 0)).ok());
}

}  // namespace
}  // namespace optique::image
