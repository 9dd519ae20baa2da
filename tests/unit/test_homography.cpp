#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "calib/homography.h"

namespace optique::calib {
namespace {

// Projector homographies from mild keystone to grazing, with 8K pixel coordinates.
glm::dmat3 make_h(double a11, double a12, double a13, double a21, double a22, double a23, double a31, double a32) {
  glm::dmat3 h(1.0);
  h[0][0] = a11, h[1][0] = a12, h[2][0] = a13;
  h[0][1] = a21, h[1][1] = a22, h[2][1] = a23;
  h[0][2] = a31, h[1][2] = a32, h[2][2] = 1.0;
  return h;
}

std::vector<Correspondence> grid(const glm::dmat3& h, int n, double width, double height) {
  std::vector<Correspondence> points;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const glm::dvec2 s(width * (0.05 + 0.9 * i / (n - 1)), height * (0.05 + 0.9 * j / (n - 1)));
      points.push_back({s, apply(h, s)});
    }
  }
  return points;
}

struct Case {
  const char* name;
  glm::dmat3 h;
};

const Case kCases[] = {
    {"mild keystone", make_h(400, 20, 100, -10, -380, 900, 0.01, 0.02)},
    {"strong oblique", make_h(900, 150, 200, 80, -700, 1800, 0.25, 0.05)},
    {"grazing", make_h(2000, 400, 50, 300, -1200, 3000, 0.9, 0.1)},
    {"8K pixels", make_h(1900, 30, 150, 20, -1900, 4300, 0.002, 0.001)},
};

TEST(FitHomography, ExactPointsGiveTheHomographyBack) {
  for (const auto& c : kCases) {
    const auto points = grid(c.h, 5, 4.0, 2.25);
    auto fit = fit_homography(points);
    ASSERT_TRUE(fit.ok()) << c.name << ": " << fit.error();
    EXPECT_LE(fit.value().max_px, 1e-6) << c.name;
    for (const auto& p : points) {
      const glm::dvec2 q = apply(fit.value().homography, p.screen);
      EXPECT_NEAR(q.x, p.pixel.x, 1e-6) << c.name;
      EXPECT_NEAR(q.y, p.pixel.y, 1e-6) << c.name;
    }
    EXPECT_NEAR(fit.value().homography[2][2], 1.0, 1e-12);
  }
}

TEST(FitHomography, NoisyPointsFitToAboutTheNoise) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (const auto& c : kCases) {
    auto points = grid(c.h, 5, 4.0, 2.25);  // 25 points
    for (auto& p : points) p.pixel += glm::dvec2(noise(random), noise(random));
    auto fit = fit_homography(points);
    ASSERT_TRUE(fit.ok()) << c.name;
    // Residual distance RMS of a least-squares fit: σ·√2 per point (two coordinates),
    // less the 8 fitted parameters out of 2·25 numbers: σ·√2·√(1 − 8/50) ≈ 0.648 px.
    const double expected = 0.5 * std::sqrt(2.0) * std::sqrt(1.0 - 8.0 / 50.0);
    EXPECT_NEAR(fit.value().rms_px, expected, 0.3 * expected) << c.name;
  }
}

TEST(FitHomography, DegenerateInputIsRefusedWithAReason) {
  const glm::dmat3 h = kCases[0].h;
  auto few = grid(h, 2, 4.0, 2.25);
  few.pop_back();
  auto result = fit_homography(few);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("at least 4"), std::string::npos);

  std::vector<Correspondence> line;
  for (int i = 0; i < 6; ++i) line.push_back({{0.5 * i, 0.25 * i}, apply(h, {0.5 * i, 0.25 * i})});
  result = fit_homography(line);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("one line"), std::string::npos) << result.error();

  auto repeated = grid(h, 3, 4.0, 2.25);
  repeated.push_back(repeated.front());
  result = fit_homography(repeated);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("repeats"), std::string::npos) << result.error();

  auto nan = grid(h, 3, 4.0, 2.25);
  nan[2].pixel.x = std::nan("");
  result = fit_homography(nan);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("points[2]"), std::string::npos) << result.error();
}

}  // namespace
}  // namespace optique::calib
