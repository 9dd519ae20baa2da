// A glTF animation evaluated at any time: scene_load/gltf_animation.h.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/definition.h"
#include "scene_load/gltf_animation.h"

namespace optique::scene::gltf {
namespace {

constexpr double kTol = 1e-12;

Sampler vectors(Interpolation interpolation, std::vector<double> times, std::vector<double> values) {
  Sampler s;
  s.interpolation = interpolation;
  s.times = std::move(times);
  s.values = std::move(values);
  return s;
}

// (x, y, z, w) of a turn of `angle` about z.
std::vector<double> about_z(double angle) { return {0.0, 0.0, std::sin(angle / 2), std::cos(angle / 2)}; }

TEST(GltfAnimation, StepHoldsEachKeyUntilTheNext) {
  const Sampler s = vectors(Interpolation::kStep, {0.0, 1.0}, {1, 2, 3, 4, 5, 6});
  EXPECT_EQ(s.at(0.99), glm::dvec4(1, 2, 3, 0));
  EXPECT_EQ(s.at(1.0), glm::dvec4(4, 5, 6, 0));
}

TEST(GltfAnimation, LinearMixesAndHoldsTheEndsOutside) {
  const Sampler s = vectors(Interpolation::kLinear, {1.0, 3.0}, {0, 0, 0, 2, 4, -6});
  EXPECT_EQ(s.at(0.0), glm::dvec4(0, 0, 0, 0));  // before the first key: the first value
  EXPECT_EQ(s.at(9.0), glm::dvec4(2, 4, -6, 0));
  const glm::dvec4 half = s.at(2.5);
  EXPECT_NEAR(half.x, 1.5, kTol);
  EXPECT_NEAR(half.y, 3.0, kTol);
  EXPECT_NEAR(half.z, -4.5, kTol);
}

TEST(GltfAnimation, LinearRotationsSlerpAndStayUnit) {
  Sampler s;
  s.rotation = true;
  s.times = {0.0, 1.0};
  s.values = about_z(0.0);
  const auto quarter = about_z(std::numbers::pi / 2);
  s.values.insert(s.values.end(), quarter.begin(), quarter.end());
  // A quarter of the way: a turn of π/8 (the normalized mix of the ends turns
  // by less).
  const glm::dvec4 q = s.at(0.25);
  const auto expected = about_z(std::numbers::pi / 8);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(q[i], expected[static_cast<std::size_t>(i)], 1e-12) << i;
  EXPECT_NEAR(glm::length(q), 1.0, kTol);
}

TEST(GltfAnimation, CubicSplineFollowsItsTangents) {
  // In-tangent, value, out-tangent per key: x from 0 to 1 over 2 s, leaving
  // key 0 and reaching key 1 at a slope of 1 per second. Hermite: p(u) =
  // h00·v0 + h10·span·out0 + h01·v1 + h11·span·in1.
  const Sampler s = vectors(Interpolation::kCubicSpline, {0.0, 2.0},
                            {0, 0, 0, 0, 0, 0, 1, 0, 0,    // key 0: in, value 0, out 1
                             1, 0, 0, 1, 0, 0, 0, 0, 0});  // key 1: in 1, value 1, out
  // u = 0.5: 0.125·2 + 0.5 − 0.125·2.
  EXPECT_NEAR(s.at(1.0).x, 0.5, kTol);
  // u = 0.25: h10 = 0.140625, h01 = 0.15625, h11 = −0.046875.
  EXPECT_NEAR(s.at(0.5).x, 0.140625 * 2 + 0.15625 - 0.046875 * 2, kTol);
  Sampler steep = s;
  steep.values[6] = 2.0;  // key 0 leaves twice as steeply
  EXPECT_NEAR(steep.at(0.5).x, 0.140625 * 2 * 2 + 0.15625 - 0.046875 * 2, kTol);
}

TEST(GltfAnimation, TrackTimeWrapsIntoItsDuration) {
  Track track;
  track.duration = 2.0;
  EXPECT_NEAR(track.wrap(5.5), 1.5, kTol);
  EXPECT_NEAR(track.wrap(-0.5), 1.5, kTol);
  EXPECT_EQ(track.wrap(std::numeric_limits<double>::quiet_NaN()), 0.0);
  EXPECT_EQ(track.wrap(std::numeric_limits<double>::infinity()), 0.0);
  track.duration = 0.0;
  EXPECT_EQ(track.wrap(3.0), 0.0);
}

TEST(GltfAnimation, TrackComposesItsLinksUnderItsBase) {
  Track track;
  track.duration = 1.0;
  track.base = glm::translate(glm::dmat4(1.0), glm::dvec3(10, 0, 0));
  Link link;
  link.animated = true;
  link.translation_track = vectors(Interpolation::kLinear, {0.0, 1.0}, {0, 0, 0, 0, 4, 0});
  track.links.push_back(link);
  const Pose pose = track.pose_at(1.25);  // wraps to 0.25
  EXPECT_NEAR(pose.position.x, 10.0, kTol);
  EXPECT_NEAR(pose.position.y, 1.0, kTol);
}

TEST(GltfAnimation, DecomposeGivesThePoseBack) {
  Pose pose;
  pose.position = {1, -2, 3};
  pose.rotation = glm::angleAxis(0.7, glm::normalize(glm::dvec3(1, 2, 3)));
  pose.scale = {2, 3, 4};
  const glm::dmat4 m = model_matrix(pose);
  const Pose back = decompose(m);
  EXPECT_TRUE(reproduces(back, m));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(back.position[i], pose.position[i], 1e-12);
    EXPECT_NEAR(back.scale[i], pose.scale[i], 1e-12);
  }
  EXPECT_NEAR(std::abs(glm::dot(back.rotation, pose.rotation)), 1.0, 1e-12);
  EXPECT_GE(back.rotation.w, 0.0);  // canonical
}

TEST(GltfAnimation, AMirrorIsANegativeXScaleAndShearIsNotAPose) {
  const glm::dmat4 mirror = glm::scale(glm::dmat4(1.0), glm::dvec3(1, -1, 1));
  const Pose mirrored = decompose(mirror);
  EXPECT_LT(mirrored.scale.x, 0.0);
  EXPECT_TRUE(reproduces(mirrored, mirror));
  glm::dmat4 shear(1.0);
  shear[1][0] = 0.5;  // y leans into x
  EXPECT_FALSE(reproduces(decompose(shear), shear));
}

TEST(GltfAnimation, AnAxisScaledToZeroStillGivesAFinitePose) {
  const glm::dmat4 flat = glm::scale(glm::dmat4(1.0), glm::dvec3(2, 0, 1));
  const Pose pose = decompose(flat);
  EXPECT_TRUE(finite(pose));
  EXPECT_TRUE(reproduces(pose, flat));
}

}  // namespace
}  // namespace optique::scene::gltf
