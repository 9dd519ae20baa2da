// The automatic light split (master/run/light_share.h) and the coverage estimate it
// runs on (common/scene/light_coverage.h): every light in exactly one share, the
// ambient in exactly one, modelled times balanced.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "master/run/light_share.h"
#include "master/run/scene_authority.h"
#include "scene/builtin.h"
#include "scene/light_coverage.h"
#include "scene/meshes.h"

namespace optique::master {
namespace {

constexpr double kPixels = 1920.0 * 1080.0;

std::vector<std::uint32_t> range(std::uint32_t first, std::uint32_t end) {
  std::vector<std::uint32_t> v(end - first);
  std::iota(v.begin(), v.end(), first);
  return v;
}

// Every light in exactly one share, each share ascending, the ambient in exactly one.
void expect_partition(const std::vector<LightShare>& shares, std::size_t light_count) {
  std::vector<int> seen(light_count, 0);
  int ambient = 0;
  for (const LightShare& share : shares) {
    EXPECT_TRUE(std::is_sorted(share.lights.begin(), share.lights.end()));
    for (const std::uint32_t light : share.lights) {
      ASSERT_LT(light, light_count);
      ++seen[light];
    }
    ambient += share.ambient ? 1 : 0;
  }
  EXPECT_EQ(ambient, 1);
  for (std::size_t i = 0; i < light_count; ++i) EXPECT_EQ(seen[i], 1) << "light " << i;
}

std::vector<std::size_t> counts(const std::vector<LightShare>& shares) {
  std::vector<std::size_t> n;
  for (const LightShare& share : shares) n.push_back(share.lights.size());
  return n;
}

// Costs in [0, 1], scattered but the same on every run.
std::vector<double> scattered_costs(std::size_t n) {
  std::vector<double> costs;
  std::uint32_t x = 12345;
  for (std::size_t i = 0; i < n; ++i) {
    x = x * 1664525u + 1013904223u;
    costs.push_back(static_cast<double>(x >> 8) / static_cast<double>(1u << 24));
  }
  return costs;
}

TEST(ShareLights, EqualLightsOverEqualNodesSplitSevenSevenSix) {
  const std::vector<double> costs(20, 1.0);
  const std::vector<double> pixels(3, kPixels);
  const auto shares = share_lights(costs, pixels, 0.5, 0.3);
  ASSERT_EQ(shares.size(), 3u);
  expect_partition(shares, costs.size());
  auto n = counts(shares);
  std::sort(n.begin(), n.end());
  EXPECT_EQ(n, (std::vector<std::size_t>{6, 7, 7}));
  // The ambient weighs something, so its carrier takes the smaller share.
  for (const LightShare& share : shares) {
    if (share.ambient) {
      EXPECT_EQ(share.lights.size(), 6u);
    }
  }
}

TEST(ShareLights, LightsThatReachNothingStillCount) {
  // Zero coverage counts as the floor, so such lights spread out like equal ones
  // instead of piling onto one node.
  const std::vector<double> costs(20, 0.0);
  const std::vector<double> pixels(3, kPixels);
  const auto shares = share_lights(costs, pixels, 1.0, 0.0);
  expect_partition(shares, costs.size());
  auto n = counts(shares);
  std::sort(n.begin(), n.end());
  EXPECT_EQ(n, (std::vector<std::size_t>{6, 7, 7}));
  const auto times = modelled_times(costs, pixels, 1.0, 0.0, shares);
  EXPECT_DOUBLE_EQ(times[0], kPixels * (1.0 + static_cast<double>(shares[0].lights.size()) * kLightCostFloor));
}

TEST(ShareLights, ANodeWithTwiceThePixelsTakesHalfTheLights) {
  const std::vector<double> costs(30, 1.0);
  const std::vector<double> pixels{2.0 * kPixels, kPixels, kPixels};
  const auto shares = share_lights(costs, pixels, 0.0, 0.0);
  expect_partition(shares, costs.size());
  const auto n = counts(shares);
  EXPECT_EQ(n[1], n[2]);
  EXPECT_NEAR(static_cast<double>(n[0]), static_cast<double>(n[1]) / 2.0, 1.0);
  EXPECT_EQ(n[0] + n[1] + n[2], 30u);
}

TEST(ShareLights, TheAmbientGoesToTheFastestNode) {
  const std::vector<double> costs(4, 1.0);
  const std::vector<double> pixels{3.0 * kPixels, kPixels, 2.0 * kPixels};
  const auto shares = share_lights(costs, pixels, 1.0, 0.5);
  expect_partition(shares, costs.size());
  EXPECT_TRUE(shares[1].ambient);
}

TEST(ShareLights, UnequalCostsBalanceTheModelledTimes) {
  const std::vector<double> costs = scattered_costs(24);
  for (const std::vector<double>& pixels :
       {std::vector<double>(3, kPixels), std::vector<double>{kPixels, 1.5 * kPixels, 0.7 * kPixels, kPixels}}) {
    const auto shares = share_lights(costs, pixels, 0.2, 0.4);
    expect_partition(shares, costs.size());
    const auto times = modelled_times(costs, pixels, 0.2, 0.4, shares);
    ASSERT_EQ(times.size(), pixels.size());
    // Greedy LPT: no node is behind another by more than the largest single job.
    const double largest_cost = std::max(*std::max_element(costs.begin(), costs.end()), 0.4);
    const double largest_job = *std::max_element(pixels.begin(), pixels.end()) * largest_cost;
    const auto [fastest, slowest] = std::minmax_element(times.begin(), times.end());
    EXPECT_LE(*slowest - *fastest, largest_job);
    // And much better than everything on one node.
    double all = 0.0;
    for (const double c : costs) all += std::max(c, kLightCostFloor);
    EXPECT_LT(*slowest, 0.6 * pixels[0] * all);
  }
}

TEST(ShareLights, ModelledTimesFollowTheModel) {
  const std::vector<double> costs{0.5, 0.0, 1.0};
  const std::vector<double> pixels{100.0, 200.0};
  const std::vector<LightShare> shares{{{0, 1}, true}, {{2}, false}};
  const auto times = modelled_times(costs, pixels, 0.25, 2.0, shares);
  EXPECT_DOUBLE_EQ(times[0], 100.0 * (0.25 + 0.5 + kLightCostFloor + 2.0));
  EXPECT_DOUBLE_EQ(times[1], 200.0 * (0.25 + 1.0));
}

TEST(ShareLights, MoreNodesThanLights) {
  const std::vector<double> costs{0.3, 0.9, 0.6};
  const std::vector<double> pixels(5, kPixels);
  const auto shares = share_lights(costs, pixels, 1.0, 0.2);
  expect_partition(shares, costs.size());
  for (const LightShare& share : shares) {
    EXPECT_LE(share.lights.size(), 1u);
    if (share.ambient) {
      EXPECT_TRUE(share.lights.empty());
    }
  }
}

TEST(ShareLights, ZeroLights) {
  const std::vector<double> pixels(3, kPixels);
  const auto shares = share_lights({}, pixels, 1.0, 0.2);
  ASSERT_EQ(shares.size(), 3u);
  expect_partition(shares, 0);
  EXPECT_TRUE(shares[0].ambient);  // all equal: the lowest index
  for (const LightShare& share : shares) EXPECT_TRUE(share.lights.empty());
  const auto times = modelled_times({}, pixels, 1.0, 0.2, shares);
  EXPECT_DOUBLE_EQ(times[0], kPixels * 1.2);
  EXPECT_DOUBLE_EQ(times[2], kPixels);
}

TEST(ShareLights, OneNodeTakesEverything) {
  const std::vector<double> costs = scattered_costs(7);
  const auto shares = share_lights(costs, std::vector<double>{kPixels}, 1.0, 0.2);
  ASSERT_EQ(shares.size(), 1u);
  EXPECT_EQ(shares[0].lights, range(0, 7));
  EXPECT_TRUE(shares[0].ambient);
}

TEST(ShareLights, IsDeterministic) {
  const std::vector<double> costs = scattered_costs(40);
  const std::vector<double> pixels{kPixels, 0.5 * kPixels, kPixels, 2.0 * kPixels};
  const auto first = share_lights(costs, pixels, 0.3, 0.1);
  for (int run = 0; run < 5; ++run) {
    const auto again = share_lights(costs, pixels, 0.3, 0.1);
    ASSERT_EQ(again.size(), first.size());
    for (std::size_t i = 0; i < first.size(); ++i) {
      EXPECT_EQ(again[i].lights, first[i].lights);
      EXPECT_EQ(again[i].ambient, first[i].ambient);
    }
  }
  // Ties go to the lowest index: equal lights deal out round-robin from node 0.
  const auto dealt = share_lights(std::vector<double>(6, 1.0), std::vector<double>(3, kPixels), 1.0, 0.0);
  EXPECT_EQ(dealt[0].lights, (std::vector<std::uint32_t>{0, 3}));
  EXPECT_EQ(dealt[1].lights, (std::vector<std::uint32_t>{1, 4}));
  EXPECT_EQ(dealt[2].lights, (std::vector<std::uint32_t>{2, 5}));
}

// --- the coverage the costs come from ---

scene::SceneDefinition builtin(std::string_view name) {
  auto scene = scene::builtin_scene(name);
  EXPECT_TRUE(scene.ok()) << scene.error();
  return scene.ok() ? std::move(scene).value() : scene::SceneDefinition{};
}

scene::SceneState frame_zero(const scene::SceneDefinition& scene) {
  config::Viewer viewer;
  viewer.path = {{0.0, {0.0, 1.2, 2.0}}};
  return SceneAuthority(scene.objects, viewer, 60.0).state_at_frame(0);
}

// The front of the stage seen from (0, 1.2, 2): the screen plane z = 0.
scene::CoverageGrid stage_front() {
  scene::CoverageGrid grid;
  grid.eye = {0.0, 1.2, 2.0};
  grid.corner = {-1.6, 0.3, 0.0};
  grid.across = {3.2, 0.0, 0.0};
  grid.up = {0.0, 1.8, 0.0};
  return grid;
}

TEST(LightCoverage, ManyLightsFromTheFront) {
  const scene::SceneDefinition scene = builtin("many-lights");
  const auto coverage = scene::light_coverage(scene, frame_zero(scene), stage_front());
  ASSERT_EQ(coverage.size(), scene.lights.size());
  for (const double c : coverage) {
    EXPECT_GE(c, 0.0);
    EXPECT_LE(c, 1.0);
  }
  // The wall behind the statue fills the view and every light stands in front
  // of it: each reaches most of what is seen, but not the same share (the
  // statue's faces turned away from a light, and the far corners, differ).
  EXPECT_GT(*std::min_element(coverage.begin(), coverage.end()), 0.5);
  EXPECT_GT(*std::max_element(coverage.begin(), coverage.end()), *std::min_element(coverage.begin(), coverage.end()));

  // What the split makes of it: every light placed, one ambient.
  std::vector<double> pixels(3, kPixels);
  const auto shares = share_lights(coverage, pixels, 0.5, 0.1);
  expect_partition(shares, scene.lights.size());
}

// A 4 m square quad at z = −1 facing +z, seen from z = 1 over its middle 2 m.
struct QuadView {
  scene::SceneDefinition scene;
  scene::CoverageGrid grid;
};

QuadView quad_view() {
  QuadView view;
  view.scene.meshes.push_back(scene::make_quad(4.0f, 4.0f));
  view.scene.materials.push_back({});
  view.scene.instances.push_back({0, 0, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.0, -1.0))});
  view.grid.eye = {0.0, 0.0, 1.0};
  view.grid.corner = {-1.0, -1.0, -1.0};
  view.grid.across = {2.0, 0.0, 0.0};
  view.grid.up = {0.0, 2.0, 0.0};
  return view;
}

TEST(LightCoverage, ALightBehindTheSurfaceReachesNothing) {
  QuadView view = quad_view();
  view.scene.lights.push_back({{0.0, 0.0, -2.0}, glm::vec3(1.0f), 10.0f});
  EXPECT_EQ(scene::light_coverage(view.scene, {}, view.grid), std::vector<double>{0.0});
}

TEST(LightCoverage, ALightRightInFrontReachesMost) {
  QuadView view = quad_view();
  view.scene.lights.push_back({{0.0, 0.0, -0.9}, glm::vec3(1.0f), 1.0f});
  view.scene.lights.push_back({{0.0, 0.0, -0.9}, glm::vec3(1.0f), 1e-6f});               // too faint to notice
  view.scene.lights.push_back({{0.5, 0.5, -0.99}, glm::vec3(0.0f, 0.2f, 0.0f), 0.05f});  // a small pool
  const auto coverage = scene::light_coverage(view.scene, {}, view.grid);
  ASSERT_EQ(coverage.size(), 3u);
  EXPECT_GT(coverage[0], 0.5);
  EXPECT_EQ(coverage[1], 0.0);
  EXPECT_GT(coverage[2], 0.0);
  EXPECT_LT(coverage[2], 0.5);
}

TEST(LightCoverage, RaysThatMeetNothingCountForNoLight) {
  QuadView view = quad_view();
  view.scene.lights.push_back({{0.0, 0.0, 0.5}, glm::vec3(1.0f), 100.0f});
  view.grid.corner = {3.0, 3.0, -1.0};  // beside the quad
  EXPECT_EQ(scene::light_coverage(view.scene, {}, view.grid), std::vector<double>{0.0});
  EXPECT_TRUE(scene::light_coverage(scene::SceneDefinition{}, {}, view.grid).empty());
}

}  // namespace
}  // namespace optique::master
