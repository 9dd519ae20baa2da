// Hard cases for the calibration fit: which ones are errors, which warnings
// (each with its measured reason), and what robust mode does with outliers.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "calib/fit.h"
#include "pinhole_projector.h"

namespace optique::calib {
namespace {

using testing::PinholeProjector;

constexpr double kSigma = 0.5;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The first warning containing `part`, or "" when none does.
std::string warning_with(const HomographyFit& fit, const std::string& part) {
  for (const auto& w : fit.warnings) {
    if (contains(w, part)) return w;
  }
  return "";
}

std::string all_warnings(const HomographyFit& fit) {
  std::string text;
  for (const auto& w : fit.warnings) text += "\n  " + w;
  return text;
}

FitOptions with_image(const PinholeProjector& p, bool robust = false) {
  FitOptions options;
  options.image = geometry::ImageSize{p.width, p.height};
  options.robust = robust;
  return options;
}

// Points at the given pixels, with their exact screen points.
std::vector<geometry::Correspondence> at_pixels(const glm::dmat3& h, const std::vector<glm::dvec2>& pixels) {
  std::vector<geometry::Correspondence> points;
  for (const auto& p : pixels) points.push_back({geometry::apply(glm::inverse(h), p), p});
  return points;
}

PinholeProjector mild() { return testing::projector_cases()[0]; }
PinholeProjector oblique() { return testing::projector_cases()[1]; }

// A projector `incidence_deg` off the screen normal at the centre of its image;
// the focal length sets how far past that its image edges go.
PinholeProjector near_horizon(double incidence_deg, double focal_px) {
  const double a = incidence_deg * std::numbers::pi / 180.0;
  const glm::dvec3 centre(2.0, 1.1, 0.0);
  return {"near horizon", 1920, 1080, focal_px, {960, 540}, centre + 4.0 * glm::dvec3(-std::sin(a), 0.0, std::cos(a)),
          centre,         0.0};
}

TEST(CalibrationDiagnostics, ThreeOfFourOnALineIsAnError) {
  PinholeProjector p = mild();
  p.width = 2560;
  p.height = 1440;
  p.principal = {1280, 720};
  const auto points = at_pixels(p.homography(), {{280, 700}, {1280, 700}, {2280, 700}, {1280, 1300}});
  auto fit = fit_homography(points, with_image(p));
  ASSERT_FALSE(fit.ok());
  EXPECT_TRUE(contains(fit.error(), "points[0], points[1] and points[2] lie on one line")) << fit.error();
  EXPECT_TRUE(contains(fit.error(), "fix no homography")) << fit.error();
}

TEST(CalibrationDiagnostics, ThreeOfFourNearlyOnALineWarnsWithTheDistance) {
  PinholeProjector p = mild();
  p.width = 2560;
  p.height = 1440;
  p.principal = {1280, 720};
  // points[1] is 0.01 px off the line through the other two, 2000 px apart.
  const auto points = at_pixels(p.homography(), {{280, 700}, {1280, 700.01}, {2280, 700}, {1280, 1300}});
  auto fit = fit_homography(points, with_image(p));
  ASSERT_TRUE(fit.ok()) << fit.error();
  const std::string warning = warning_with(fit.value(), "nearly on one line on the pixel side");
  ASSERT_FALSE(warning.empty()) << all_warnings(fit.value());
  EXPECT_TRUE(contains(warning, "points[0], points[1] and points[2]")) << warning;
  EXPECT_TRUE(contains(warning, "points[1] is 0.01 px from the line")) << warning;
  EXPECT_TRUE(contains(warning, "2000 px apart")) << warning;

  // Among many points the same three do not matter.
  auto many = testing::grid_points(p.homography(), p.width, p.height, 5, 4);
  many.insert(many.end(), points.begin(), points.begin() + 3);
  auto fit_many = fit_homography(many, with_image(p));
  ASSERT_TRUE(fit_many.ok()) << fit_many.error();
  EXPECT_TRUE(warning_with(fit_many.value(), "nearly on one line").empty()) << all_warnings(fit_many.value());
}

TEST(CalibrationDiagnostics, PointsInACornerWarnWithTheCoverage) {
  const PinholeProjector p = mild();
  std::vector<glm::dvec2> pixels;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) pixels.emplace_back(50.0 + 100.0 * i, 50.0 + 100.0 * j);  // 400 × 300 px
  }
  auto fit = fit_homography(at_pixels(p.homography(), pixels), with_image(p));
  ASSERT_TRUE(fit.ok()) << fit.error();
  ASSERT_TRUE(fit.value().coverage.has_value());
  EXPECT_NEAR(*fit.value().coverage, 400.0 * 300.0 / (1920.0 * 1080.0), 1e-9);
  const std::string warning = warning_with(fit.value(), "extrapolates");
  ASSERT_FALSE(warning.empty()) << all_warnings(fit.value());
  EXPECT_TRUE(contains(warning, "cover 5.8% of the 1920×1080 image")) << warning;
  EXPECT_TRUE(contains(warning, "400×300 px")) << warning;

  auto spread = fit_homography(testing::grid_points(p.homography(), p.width, p.height, 5, 4), with_image(p));
  ASSERT_TRUE(spread.ok());
  EXPECT_GT(*spread.value().coverage, 0.8);
  EXPECT_TRUE(spread.value().warnings.empty()) << all_warnings(spread.value());
}

TEST(CalibrationDiagnostics, OneGrossOutlierIsNamedWithoutRobustMode) {
  const PinholeProjector p = oblique();
  std::mt19937_64 random(21);
  auto points =
      testing::with_pixel_noise(testing::grid_points(p.homography(), p.width, p.height, 5, 4), kSigma, random);
  points[7].pixel += glm::dvec2(40.0, -30.0);  // 50 px off
  auto fit = fit_homography(points, with_image(p));
  ASSERT_TRUE(fit.ok()) << fit.error();
  ASSERT_EQ(fit.value().outliers.size(), 1u) << all_warnings(fit.value());
  EXPECT_EQ(fit.value().outliers.front().index, 7u);
  const std::string warning = warning_with(fit.value(), "points[7] is ");
  ASSERT_FALSE(warning.empty()) << all_warnings(fit.value());
  EXPECT_TRUE(contains(warning, "median residual")) << warning;
  EXPECT_TRUE(contains(warning, "--robust")) << warning;
}

TEST(CalibrationDiagnostics, RobustModeLeavesTheOutlierOutAndFitsToTheNoise) {
  const PinholeProjector p = oblique();
  const glm::dmat3 truth = p.homography();
  const auto exact = testing::grid_points(truth, p.width, p.height, 5, 4);
  std::mt19937_64 random(5);
  constexpr int kTrials = 100;
  double sum = 0.0;
  for (int t = 0; t < kTrials; ++t) {
    auto points = testing::with_pixel_noise(exact, kSigma, random);
    points[7].pixel += glm::dvec2(40.0, -30.0);
    auto fit = fit_homography(points, with_image(p, /*robust=*/true));
    ASSERT_TRUE(fit.ok()) << fit.error();
    ASSERT_EQ(fit.value().outliers.size(), 1u) << "trial " << t << all_warnings(fit.value());
    EXPECT_EQ(fit.value().outliers.front().index, 7u);
    EXPECT_GT(fit.value().outliers.front().residual_px, 45.0);
    EXPECT_EQ(fit.value().inliers.size(), 19u);
    const std::string warning = warning_with(fit.value(), "left out 1 of 20 points");
    EXPECT_TRUE(contains(warning, "points[7]")) << all_warnings(fit.value());
    const double e = testing::transfer_error(fit.value().homography, truth, exact);
    sum += e * e;
  }
  // Within noise of the truth: the optimum for the 19 inliers.
  const double optimum = kSigma * std::sqrt(8.0 / (2.0 * 19.0));
  const double rms = std::sqrt(sum / kTrials);
  std::printf("robust, one outlier: transfer error %.4f px, optimum for 19 inliers %.4f px\n", rms, optimum);
  EXPECT_NEAR(rms, optimum, 0.15 * optimum);
}

TEST(CalibrationDiagnostics, RobustModeFindsManyOutliersAndIsDeterministic) {
  const PinholeProjector p = testing::projector_cases()[3];  // 8K
  const glm::dmat3 truth = p.homography();
  const auto exact = testing::grid_points(truth, p.width, p.height, 8, 5);
  std::mt19937_64 random(8);
  auto points = testing::with_pixel_noise(exact, kSigma, random);
  std::uniform_real_distribution<double> far(-400.0, 400.0);
  const std::vector<std::size_t> bad{1, 6, 12, 13, 20, 27, 33, 34, 38, 39, 17, 25};  // 30 %
  for (const std::size_t i : bad) points[i].pixel += glm::dvec2(far(random), 100.0 + std::abs(far(random)));
  auto first = fit_homography(points, with_image(p, true));
  ASSERT_TRUE(first.ok()) << first.error();
  std::vector<std::size_t> found;
  for (const auto& o : first.value().outliers) found.push_back(o.index);
  std::sort(found.begin(), found.end());
  auto expected = bad;
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(found, expected);
  EXPECT_LT(testing::transfer_error(first.value().homography, truth, exact), 0.5);
  auto second = fit_homography(points, with_image(p, true));
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(first.value().homography, second.value().homography);
}

// The screen origin on the projector's horizon: h33 = 0 in the true H.
TEST(CalibrationDiagnostics, OriginOnTheHorizonGivesAFiniteFitWithTheRightTransfer) {
  const PinholeProjector p = oblique();
  const glm::dmat3 h = p.homography();
  // The point of the horizon line h31·X + h32·Y + h33 = 0 closest to the origin.
  const glm::dvec2 n(h[0][2], h[1][2]);
  const glm::dvec2 on_horizon = -h[2][2] * n / glm::dot(n, n);
  glm::dmat3 shift(1.0);
  shift[2] = glm::dvec3(on_horizon, 1.0);
  const glm::dmat3 truth = h * shift;  // screen' = screen − on_horizon
  ASSERT_LT(std::abs(truth[2][2]), 1e-12 * std::abs(truth[0][0]));

  const auto exact = testing::grid_points(truth, p.width, p.height, 5, 4);
  auto fit = fit_homography(exact, with_image(p));
  ASSERT_TRUE(fit.ok()) << fit.error();
  const glm::dmat3& g = fit.value().homography;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) EXPECT_TRUE(std::isfinite(g[c][r]));
  }
  EXPECT_LE(fit.value().max_px, 1e-6);
  const std::string warning = warning_with(fit.value(), "h33 ≈ 0");
  EXPECT_TRUE(contains(warning, "horizon")) << all_warnings(fit.value());

  std::mt19937_64 random(3);
  double sum = 0.0;
  constexpr int kTrials = 100;
  for (int t = 0; t < kTrials; ++t) {
    auto noisy = fit_homography(testing::with_pixel_noise(exact, kSigma, random), with_image(p));
    ASSERT_TRUE(noisy.ok()) << noisy.error();
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) ASSERT_TRUE(std::isfinite(noisy.value().homography[c][r]));
    }
    const double e = testing::transfer_error(noisy.value().homography, truth, exact);
    sum += e * e;
  }
  const double optimum = kSigma * std::sqrt(8.0 / 40.0);
  EXPECT_NEAR(std::sqrt(sum / kTrials), optimum, 0.15 * optimum);
}

TEST(CalibrationDiagnostics, ObliqueDepthFactorNearOneWarns) {
  // 63° at the centre, a short-throw lens: the far edge meets the screen at 88.6°.
  const PinholeProjector steep = near_horizon(63.0, 2000.0);
  auto fit =
      fit_homography(testing::grid_points(steep.homography(), steep.width, steep.height, 5, 4), with_image(steep));
  ASSERT_TRUE(fit.ok()) << fit.error();
  ASSERT_TRUE(fit.value().oblique.has_value());
  const geometry::ObliqueDepth& d = *fit.value().oblique;
  EXPECT_GE(d.factor, geometry::kDepthFactorWarning);
  EXPECT_LT(d.factor, 1.0);
  const std::string warning = warning_with(fit.value(), "|a31| + |a32| is 0.9");
  EXPECT_FALSE(warning.empty()) << all_warnings(fit.value());

  // A is N_p · H · N_u⁻¹: it takes each image corner's point on the screen, in
  // user NDC through R, to that corner in projector NDC.
  const glm::dmat3 inverse = glm::inverse(fit.value().homography);
  for (const glm::dvec2 corner : {glm::dvec2(0, 0), glm::dvec2(1920, 0), glm::dvec2(1920, 1080), glm::dvec2(0, 1080)}) {
    const glm::dvec2 s = geometry::apply(inverse, corner);
    const glm::dvec2 user = 2.0 * (s - d.rect_min) / (d.rect_max - d.rect_min) - 1.0;
    const glm::dvec2 ndc = geometry::apply(d.a, user);
    EXPECT_NEAR(ndc.x, 2.0 * corner.x / 1920.0 - 1.0, 1e-9);
    EXPECT_NEAR(ndc.y, 1.0 - 2.0 * corner.y / 1080.0, 1e-9);
  }
  EXPECT_DOUBLE_EQ(d.a[2][2], 1.0);

  const PinholeProjector front = mild();
  auto mild_fit =
      fit_homography(testing::grid_points(front.homography(), front.width, front.height, 5, 4), with_image(front));
  ASSERT_TRUE(mild_fit.ok());
  EXPECT_LT(mild_fit.value().oblique->factor, 0.1);
  EXPECT_TRUE(warning_with(mild_fit.value(), "a31").empty()) << all_warnings(mild_fit.value());
}

TEST(CalibrationDiagnostics, ATwistedQuadrilateralFlipsOrientation) {
  const PinholeProjector p = mild();
  auto points = testing::grid_points(p.homography(), p.width, p.height, 2, 2);
  std::swap(points[2].pixel, points[3].pixel);  // bottom corners swapped: a bow tie
  auto fit = fit_homography(points, with_image(p));
  ASSERT_FALSE(fit.ok());
  EXPECT_TRUE(contains(fit.error(), "the fit flips orientation")) << fit.error();
  EXPECT_TRUE(contains(fit.error(), "opposite sides of the projector's horizon")) << fit.error();
}

TEST(CalibrationDiagnostics, RearProjectionIsMirrored) {
  PinholeProjector rear = mild();
  rear.position.z = -rear.position.z;  // behind the screen, looking at it through the back
  auto fit = fit_homography(testing::grid_points(rear.homography(), rear.width, rear.height, 5, 4), with_image(rear));
  ASSERT_TRUE(fit.ok()) << fit.error();
  EXPECT_TRUE(fit.value().orientation.mirrored());
  const std::string warning = warning_with(fit.value(), "the image is mirrored");
  ASSERT_FALSE(warning.empty()) << all_warnings(fit.value());
  EXPECT_TRUE(contains(warning, "rear projection")) << warning;
  EXPECT_TRUE(contains(warning, "y axis")) << warning;

  const PinholeProjector front = mild();
  auto front_fit =
      fit_homography(testing::grid_points(front.homography(), front.width, front.height, 5, 4), with_image(front));
  ASSERT_TRUE(front_fit.ok());
  EXPECT_FALSE(front_fit.value().orientation.mirrored());
  EXPECT_LT(front_fit.value().orientation.jacobian_det_max, 0.0);
}

TEST(CalibrationDiagnostics, HorizonAcrossTheImageIsAnError) {
  // 84° from the normal with a long lens: the image's right edge points past
  // the screen plane's horizon. Points only where the pixels do reach the screen.
  const PinholeProjector p = near_horizon(84.0, 9000.0);
  const glm::dmat3 truth = p.homography();
  std::vector<glm::dvec2> pixels;
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 5; ++i) pixels.emplace_back(100.0 + 200.0 * i, 100.0 + 280.0 * j);
  }
  const auto points = at_pixels(truth, pixels);
  for (const auto& c : points) ASSERT_GT(geometry::homogeneous_w(truth, c.screen), 0.0);  // in front of the projector
  auto fit = fit_homography(points, with_image(p));
  ASSERT_FALSE(fit.ok());
  EXPECT_TRUE(contains(fit.error(), "the projector's horizon crosses its image")) << fit.error();
  EXPECT_TRUE(contains(fit.error(), "pixel corner (1920, 0)")) << fit.error();
}

}  // namespace
}  // namespace optique::calib
