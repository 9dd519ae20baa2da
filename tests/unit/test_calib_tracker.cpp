// Calibration from 3D tracker readings: the plane of the readings, the screen
// frame derived from them (DESIGN, "Tracker to screen frame"), and the
// homography in that frame, on a synthetic tilted wall with noisy readings.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "calib/calibrate_points.h"
#include "calib/points_file.h"
#include "calib/screen_frame.h"
#include "pinhole_projector.h"

namespace optique::calib {
namespace {

constexpr double kReadingSigma = 0.0005;  // 0.5 mm per axis

// Where the tracker sees the screen frame: a wall tilted 25° about a slanted
// axis, 2 m away from the tracker's origin.
glm::dmat4 tracker_from_screen() {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(1.5, -0.4, 2.0));
  return glm::rotate(m, 25.0 * std::numbers::pi / 180.0, glm::normalize(glm::dvec3(0.3, 1.0, 0.2)));
}

glm::dvec3 direction(const glm::dmat4& m, const glm::dvec3& v) { return glm::dvec3(m * glm::dvec4(v, 0.0)); }

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

// A projector's points as tracker readings of where its grid pixels land.
PointsFile tracker_points(const testing::PinholeProjector& p, std::mt19937_64& random) {
  std::normal_distribution<double> noise(0.0, kReadingSigma);
  PointsFile file;
  file.projector = {p.width, p.height};
  file.kind = PointKind::kTracker;
  for (const auto& c : testing::grid_points(p.homography(), p.width, p.height, 6, 5)) {
    file.pixels.push_back(c.pixel);
    glm::dvec3 reading = transform_point(tracker_from_screen(), glm::dvec3(c.screen, 0.0));
    for (int k = 0; k < 3; ++k) reading[k] += noise(random);
    file.tracker.push_back(reading);
  }
  return file;
}

// Rows of the rotation part.
glm::dvec3 axis(const glm::dmat4& m, int row) { return {m[0][row], m[1][row], m[2][row]}; }

TEST(CalibrationTracker, PlaneResidualIsTheReadingNoise) {
  const auto p = testing::projector_cases()[0];
  std::mt19937_64 random(1);
  double sum = 0.0;
  constexpr int kTrials = 20;
  for (int t = 0; t < kTrials; ++t) {
    auto calibration = calibrate_points(tracker_points(p, random));
    ASSERT_TRUE(calibration.ok()) << calibration.error();
    ASSERT_TRUE(calibration.value().tracker.has_value());
    const auto& tracker = *calibration.value().tracker;
    EXPECT_GE(tracker.plane_max_m, tracker.plane_rms_m);
    sum += tracker.plane_rms_m * tracker.plane_rms_m;
  }
  // The out-of-plane part of isotropic noise, less the 3 fitted parameters of 30.
  const double expected = kReadingSigma * std::sqrt(27.0 / 30.0);
  EXPECT_NEAR(std::sqrt(sum / kTrials), expected, 0.15 * expected);
}

TEST(CalibrationTracker, DerivedFrameFollowsThePixelsAndTheHomographyFitsToTheNoise) {
  const auto p = testing::projector_cases()[0];  // no roll, symmetric about screen x = 2 m
  std::mt19937_64 random(2);
  const PointsFile input = tracker_points(p, random);
  auto calibration = calibrate_points(input);
  ASSERT_TRUE(calibration.ok()) << calibration.error();
  const auto& tracker = *calibration.value().tracker;
  EXPECT_FALSE(tracker.frame_given);
  ASSERT_TRUE(check_rigid(tracker.tracker_to_screen).ok());
  const glm::dmat4 truth = tracker_from_screen();
  // x along pixel x (the screen's x for this projector), z towards the viewer, y up.
  EXPECT_LT(angle_deg(axis(tracker.tracker_to_screen, 0), direction(truth, {1, 0, 0})), 0.2);
  EXPECT_LT(angle_deg(axis(tracker.tracker_to_screen, 1), direction(truth, {0, 1, 0})), 0.2);
  EXPECT_LT(angle_deg(axis(tracker.tracker_to_screen, 2), direction(truth, {0, 0, 1})), 0.2);
  // The origin is the first reading, on the plane.
  const glm::dvec3 first = transform_point(tracker.tracker_to_screen, input.tracker.front());
  EXPECT_NEAR(first.x, 0.0, 1e-12);
  EXPECT_NEAR(first.y, 0.0, 1e-12);
  EXPECT_LT(std::abs(first.z), 4.0 * kReadingSigma);

  // In the derived frame H reprojects within the noise (0.5 mm ≈ 0.4 px here),
  // and sends true screen points where the true H does.
  const auto& fit = calibration.value().fit;
  EXPECT_LT(fit.rms_px, 1.0);
  EXPECT_FALSE(fit.orientation.mirrored());
  EXPECT_TRUE(fit.warnings.empty()) << fit.warnings.front();
  const glm::dmat4 screen_to_derived = tracker.tracker_to_screen * truth;
  double sum = 0.0;
  const auto exact = testing::grid_points(p.homography(), p.width, p.height, 6, 5);
  for (const auto& c : exact) {
    const glm::dvec3 s = transform_point(screen_to_derived, glm::dvec3(c.screen, 0.0));
    const glm::dvec2 d = geometry::apply(fit.homography, {s.x, s.y}) - c.pixel;
    sum += glm::dot(d, d);
  }
  EXPECT_LT(std::sqrt(sum / (2.0 * static_cast<double>(exact.size()))), 0.3);
}

TEST(CalibrationTracker, RolledProjectorGivesARolledFrame) {
  auto p = testing::projector_cases()[0];
  p.roll_deg = 10.0;  // pixel x turns 10° on the screen
  std::mt19937_64 random(3);
  auto calibration = calibrate_points(tracker_points(p, random));
  ASSERT_TRUE(calibration.ok()) << calibration.error();
  const glm::dvec3 x = axis(calibration.value().tracker->tracker_to_screen, 0);
  const double turned = angle_deg(x, direction(tracker_from_screen(), {1, 0, 0}));
  EXPECT_NEAR(turned, 10.0, 0.5);
}

TEST(CalibrationTracker, GivenFrameIsSharedByASecondProjector) {
  std::mt19937_64 random(4);
  const auto first_projector = testing::projector_cases()[0];
  auto first = calibrate_points(tracker_points(first_projector, random));
  ASSERT_TRUE(first.ok()) << first.error();
  const glm::dmat4 frame = first.value().tracker->tracker_to_screen;

  const auto second_projector = testing::projector_cases()[1];
  PointsFile input = tracker_points(second_projector, random);
  input.tracker_to_screen = frame;
  auto second = calibrate_points(input);
  ASSERT_TRUE(second.ok()) << second.error();
  const auto& tracker = *second.value().tracker;
  EXPECT_TRUE(tracker.frame_given);
  EXPECT_EQ(tracker.tracker_to_screen, frame);
  EXPECT_GT(tracker.plane_rms_m, 0.5 * kReadingSigma);  // still measured
  EXPECT_LT(tracker.plane_rms_m, 1.5 * kReadingSigma);
  EXPECT_TRUE(second.value().fit.warnings.empty()) << second.value().fit.warnings.front();

  // A screen point lit by both: each projector's H, in the shared frame, finds
  // its own pixel for it.
  const glm::dmat4 screen_to_shared = frame * tracker_from_screen();
  const glm::dvec2 wall_point(2.0, 1.1);
  const glm::dvec3 shared = transform_point(screen_to_shared, glm::dvec3(wall_point, 0.0));
  for (const auto& [projector, fit] :
       {std::pair{first_projector, first.value().fit}, std::pair{second_projector, second.value().fit}}) {
    const glm::dvec2 expected = geometry::apply(projector.homography(), wall_point);
    const glm::dvec2 got = geometry::apply(fit.homography, {shared.x, shared.y});
    EXPECT_LT(glm::length(got - expected), 1.0) << projector.name;
  }

  // Another wall's frame: the readings are off its z = 0 plane.
  input.tracker_to_screen = glm::translate(frame, glm::dvec3(0.0, 0.0, 0.2));
  auto elsewhere = calibrate_points(input);
  ASSERT_TRUE(elsewhere.ok()) << elsewhere.error();
  ASSERT_FALSE(elsewhere.value().fit.warnings.empty());
  EXPECT_NE(elsewhere.value().fit.warnings.front().find("off the z = 0 plane"), std::string::npos)
      << elsewhere.value().fit.warnings.front();
}

TEST(CalibrationTracker, ReadingsOnALineAreAnError) {
  PointsFile input;
  input.projector = {1920, 1080};
  input.kind = PointKind::kTracker;
  for (int i = 0; i < 5; ++i) {
    input.pixels.emplace_back(100.0 + 300.0 * i, 100.0 + 150.0 * (i % 2));
    input.tracker.emplace_back(0.5 * i, 0.1 * i, 2.0);
  }
  auto calibration = calibrate_points(input);
  ASSERT_FALSE(calibration.ok());
  EXPECT_NE(calibration.error().find("all lie on one line"), std::string::npos) << calibration.error();
}

TEST(CalibrationTracker, MixedKindsAreAnErrorNamingThePoint) {
  const std::string text = R"({"projector": {"width": 1920, "height": 1080}, "points": [
    {"pixel": [100, 100], "tracker": [0, 0, 2]},
    {"pixel": [1800, 100], "tracker": [2, 0, 2]},
    {"pixel": [1800, 1000], "screen": [2, 1]},
    {"pixel": [100, 1000], "tracker": [0, 1, 2]}]})";
  auto parsed = parse_points_file(text, "pts.json");
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.error(),
            "pts.json: points[2]: has \"screen\" but points[0] has \"tracker\": all points must be of one kind");
}

}  // namespace
}  // namespace optique::calib
