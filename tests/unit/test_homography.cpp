// The fit on clean input: exact correspondences come back exact, noisy ones fit
// to the noise, and input that fixes no homography is refused with a reason.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "calib/fit.h"
#include "pinhole_projector.h"

namespace optique::calib {
namespace {

using testing::grid_points;
using testing::projector_cases;

TEST(FitHomography, ExactPointsGiveTheHomographyBack) {
  for (const auto& projector : projector_cases()) {
    const glm::dmat3 truth = projector.homography();
    const auto points = grid_points(truth, projector.width, projector.height, 5, 4);
    for (const bool refine : {false, true}) {
      FitOptions options;
      options.refine = refine;
      auto fit = fit_homography(points, options);
      ASSERT_TRUE(fit.ok()) << projector.name << ": " << fit.error();
      EXPECT_LE(fit.value().max_px, 1e-6) << projector.name << (refine ? " refined" : " DLT");
      for (const auto& p : points) {
        const glm::dvec2 q = geometry::apply(fit.value().homography, p.screen);
        EXPECT_NEAR(q.x, p.pixel.x, 1e-6) << projector.name;
        EXPECT_NEAR(q.y, p.pixel.y, 1e-6) << projector.name;
      }
      EXPECT_EQ(fit.value().homography[2][2], 1.0) << projector.name;
    }
  }
}

TEST(FitHomography, ExactMinimalSetGivesTheHomographyBack) {
  const auto projector = projector_cases()[1];
  const glm::dmat3 truth = projector.homography();
  const auto points = grid_points(truth, projector.width, projector.height, 2, 2);
  auto fit = fit_homography(points);
  ASSERT_TRUE(fit.ok()) << fit.error();
  EXPECT_LE(fit.value().max_px, 1e-6);
  const glm::dvec2 centre = geometry::apply(glm::inverse(truth), {960.0, 540.0});
  const glm::dvec2 q = geometry::apply(fit.value().homography, centre);
  EXPECT_NEAR(q.x, 960.0, 1e-6);
  EXPECT_NEAR(q.y, 540.0, 1e-6);
}

TEST(FitHomography, NoisyPointsFitToAboutTheNoise) {
  std::mt19937_64 random(7);
  for (const auto& projector : projector_cases()) {
    const glm::dmat3 truth = projector.homography();
    const auto points =
        testing::with_pixel_noise(grid_points(truth, projector.width, projector.height, 5, 5), 0.5, random);
    auto fit = fit_homography(points);
    ASSERT_TRUE(fit.ok()) << projector.name << ": " << fit.error();
    // Residual distance RMS of a least-squares fit: σ·√2 per point (two coordinates),
    // less the 8 fitted parameters out of 2·25 numbers: σ·√2·√(1 − 8/50) ≈ 0.648 px.
    const double expected = 0.5 * std::sqrt(2.0) * std::sqrt(1.0 - 8.0 / 50.0);
    EXPECT_NEAR(fit.value().rms_px, expected, 0.3 * expected) << projector.name;
    EXPECT_LE(fit.value().rms_px, fit.value().dlt_rms_px + 1e-12) << projector.name;
    EXPECT_TRUE(fit.value().warnings.empty()) << projector.name << ": " << fit.value().warnings.front();
  }
}

TEST(FitHomography, DegenerateInputIsRefusedWithAReason) {
  const auto projector = projector_cases()[0];
  const glm::dmat3 h = projector.homography();
  auto few = grid_points(h, projector.width, projector.height, 2, 2);
  few.pop_back();
  auto result = fit_homography(few);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("at least 4"), std::string::npos) << result.error();
  EXPECT_NE(result.error().find("got 3"), std::string::npos) << result.error();

  std::vector<geometry::Correspondence> line;
  for (int i = 0; i < 6; ++i) line.push_back({{0.5 * i, 0.25 * i}, geometry::apply(h, {0.5 * i, 0.25 * i})});
  result = fit_homography(line);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("all lie on one line"), std::string::npos) << result.error();

  // All but one on a line: no 4 of them in general position.
  auto almost_line = line;
  almost_line[3].screen.y += 0.5;
  almost_line[3].pixel = geometry::apply(h, almost_line[3].screen);
  result = fit_homography(almost_line);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("all points but points[3] lie on one line"), std::string::npos) << result.error();

  auto repeated = grid_points(h, projector.width, projector.height, 3, 3);
  repeated.push_back(repeated[4]);
  result = fit_homography(repeated);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("points[9] repeats points[4]"), std::string::npos) << result.error();

  auto nan = grid_points(h, projector.width, projector.height, 3, 3);
  nan[2].pixel.x = std::nan("");
  result = fit_homography(nan);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("points[2] has a non-finite pixel coordinate"), std::string::npos) << result.error();

  auto infinite = grid_points(h, projector.width, projector.height, 3, 3);
  infinite[5].screen.y = std::numeric_limits<double>::infinity();
  result = fit_homography(infinite);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.error().find("points[5] has a non-finite screen coordinate"), std::string::npos) << result.error();
}

}  // namespace
}  // namespace optique::calib
