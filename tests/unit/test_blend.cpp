#include "optics/blend.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "keystoned_wall.h"

namespace optique::optics {
namespace {

using testing::keystoned_quads;
using testing::keystoned_wall;
using testing::wall_area;

constexpr double kRamps[] = {0.0, 0.02, 0.1, 0.5};

TEST(KeystonedWall, QuadsAreWhereTheFixtureSays) {
  const auto group = keystoned_wall(1280, 800);
  const auto quads = keystoned_quads();
  for (std::size_t i = 0; i < group.size(); ++i) {
    const auto quad = group[i].lit_quad();
    for (std::size_t k = 0; k < 4; ++k) {
      EXPECT_NEAR(quad[k].x, quads[i][k].x, 1e-9);
      EXPECT_NEAR(quad[k].y, quads[i][k].y, 1e-9);
    }
  }
}

TEST(QuadDistance, IsTheDistanceToTheNearestEdgeWhicheverWayRound) {
  const std::array<glm::dvec2, 4> square = {glm::dvec2(0, 1), glm::dvec2(2, 1), glm::dvec2(2, 0), glm::dvec2(0, 0)};
  const std::array<glm::dvec2, 4> reversed = {square[3], square[2], square[1], square[0]};
  for (const auto& quad : {square, reversed}) {
    const QuadDistance d(quad);
    EXPECT_NEAR(d(glm::dvec2(1.0, 0.5)), 0.5, 1e-12);
    EXPECT_NEAR(d(glm::dvec2(0.1, 0.5)), 0.1, 1e-12);
    EXPECT_NEAR(d(glm::dvec2(1.7, 0.8)), 0.2, 1e-12);
    EXPECT_EQ(d(glm::dvec2(-0.1, 0.5)), 0.0);
    EXPECT_EQ(d(glm::dvec2(3.0, 3.0)), 0.0);
  }
  // A slanted edge: the distance is perpendicular to it, not along an axis.
  const QuadDistance slanted({glm::dvec2(0, 1), glm::dvec2(1, 1), glm::dvec2(2, 0), glm::dvec2(0, 0)});
  EXPECT_NEAR(slanted(glm::dvec2(1.0, 0.5)), 0.5 / std::sqrt(2.0), 1e-12);
}

TEST(BlendRolloff, IsSmoothstepOrSquare) {
  EXPECT_EQ(blend_rolloff(0.0, 0.0), 0.0);
  EXPECT_EQ(blend_rolloff(-1.0, 0.1), 0.0);
  EXPECT_NEAR(blend_rolloff(0.3, 0.0), 0.09, 1e-15);
  EXPECT_NEAR(blend_rolloff(0.05, 0.1), 0.5, 1e-15);
  EXPECT_EQ(blend_rolloff(0.1, 0.1), 1.0);
  EXPECT_EQ(blend_rolloff(2.0, 0.1), 1.0);
  // C1 at both ends of the ramp: one-sided slopes agree.
  const double h = 1e-7;
  EXPECT_NEAR((blend_rolloff(h, 0.1) - blend_rolloff(0.0, 0.1)) / h, 0.0, 1e-4);
  EXPECT_NEAR((blend_rolloff(0.1, 0.1) - blend_rolloff(0.1 - h, 0.1)) / h, 0.0, 1e-4);
}

// Two aligned projectors on a 2 m × 1 m screen, [0, 1.2] and [0.8, 2] wide: the
// weights are known in closed form.
TEST(BlendField, AlignedOverlapHasTheClosedFormWeights) {
  const geometry::ScreenRect screen{glm::dvec2(0.0), glm::dvec2(2.0, 1.0)};
  const std::vector<geometry::ProjectorGeometry> group = {
      geometry::ProjectorGeometry::make(
          geometry::aligned_homography({glm::dvec2(0.0, 0.0), glm::dvec2(1.2, 1.0)}, 1200, 1000), 1200, 1000)
          .value(),
      geometry::ProjectorGeometry::make(
          geometry::aligned_homography({glm::dvec2(0.8, 0.0), glm::dvec2(2.0, 1.0)}, 1200, 1000), 1200, 1000)
          .value()};
  // Middle of the overlap: equal shares.
  EXPECT_NEAR(blend_weight(group, 0, screen, 0.0, glm::dvec2(1.0, 0.5)), 0.5, 1e-12);
  // d0 = 0.3, d1 = 0.1: d² gives 0.09 / 0.10; a 0.2 m smoothstep gives 1 / 1.5.
  EXPECT_NEAR(blend_weight(group, 0, screen, 0.0, glm::dvec2(0.9, 0.5)), 0.9, 1e-12);
  EXPECT_NEAR(blend_weight(group, 1, screen, 0.0, glm::dvec2(0.9, 0.5)), 0.1, 1e-12);
  EXPECT_NEAR(blend_weight(group, 0, screen, 0.2, glm::dvec2(0.9, 0.5)), 1.0 / 1.5, 1e-12);
  // Outside the overlap a projector has everything, the other nothing.
  EXPECT_EQ(blend_weight(group, 0, screen, 0.0, glm::dvec2(0.5, 0.5)), 1.0);
  EXPECT_EQ(blend_weight(group, 1, screen, 0.0, glm::dvec2(0.5, 0.5)), 0.0);
  // Per-projector ramps: 0.2 m for the first, 0.05 m for the second.
  const double ramps[] = {0.2, 0.05};
  const BlendField field(group, screen, ramps);
  EXPECT_NEAR(field.weight(0, glm::dvec2(0.9, 0.5)), 1.0 / 2.0, 1e-12);            // f0 = 1, f1 = 1
  EXPECT_NEAR(field.weight(0, glm::dvec2(0.825, 0.5)), 1.0 / (1.0 + 0.5), 1e-12);  // f1 = smoothstep(½) = ½
}

TEST(BlendField, WeightsSumToOneWhereverSomeoneLightsTheScreen) {
  const auto group = keystoned_wall(1280, 800);
  std::mt19937 random(42);
  std::uniform_real_distribution<double> x(0.0, testing::kWallWidth);
  std::uniform_real_distribution<double> y(0.0, testing::kWallHeight);
  for (double ramp : kRamps) {
    const BlendField field(group, wall_area(), ramp);
    double worst = 0.0;
    int covered = 0;
    int overlapped = 0;
    for (int k = 0; k < 200000; ++k) {
      const glm::dvec2 s(x(random), y(random));
      double sum = 0.0;
      int lit = 0;
      for (std::size_t i = 0; i < group.size(); ++i) {
        const double w = field.weight(i, s);
        ASSERT_GE(w, 0.0);
        ASSERT_LE(w, 1.0);
        sum += w;
        lit += field.edge_distance(i, s) > 0.0 ? 1 : 0;
      }
      if (lit == 0) {
        EXPECT_EQ(sum, 0.0) << "(" << s.x << ", " << s.y << ")";
        EXPECT_FALSE(field.covered(s));
        continue;
      }
      EXPECT_TRUE(field.covered(s));
      ++covered;
      overlapped += lit > 1 ? 1 : 0;
      worst = std::max(worst, std::abs(sum - 1.0));
    }
    EXPECT_LE(worst, 1e-12) << "ramp " << ramp;
    // The fixture's overlaps and its gap at the bottom are really sampled.
    EXPECT_GT(overlapped, 20000);
    EXPECT_LT(covered, 200000);
    std::printf("ramp %.2f m: |Σw − 1| ≤ %.2e over %d covered points (%d in overlaps)\n", ramp, worst, covered,
                overlapped);
  }
}

TEST(BlendField, WeightsAreZeroOutsideTheUsableAreaAndOutsideTheirQuad) {
  const auto group = keystoned_wall(1280, 800);
  const auto quads = keystoned_quads();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> x(-0.3, testing::kWallWidth + 0.3);
  std::uniform_real_distribution<double> y(-0.3, testing::kWallHeight + 0.3);
  for (double ramp : kRamps) {
    const BlendField field(group, wall_area(), ramp);
    int outside_usable = 0;
    for (int k = 0; k < 100000; ++k) {
      const glm::dvec2 s(x(random), y(random));
      for (std::size_t i = 0; i < group.size(); ++i) {
        const double w = field.weight(i, s);
        if (!wall_area().contains(s)) {
          EXPECT_EQ(w, 0.0);
          ++outside_usable;
        }
        // Outside the quad: the point maps outside the projector's image.
        const glm::dvec2 p = group[i].to_pixel(s);
        const bool in_image = p.x > 0.0 && p.y > 0.0 && p.x < group[i].width() && p.y < group[i].height();
        if (!in_image) {
          EXPECT_EQ(w, 0.0) << "projector " << i << " at (" << s.x << ", " << s.y << ")";
        }
      }
    }
    EXPECT_GT(outside_usable, 10000);
  }
}

// How fast a weight may change at a point whose deepest projector is `deepest`
// metres inside its quad: d² shares change by at most ~1.3/deepest per metre
// (shares of two distances that move by at most 1 per metre), smoothstep adds
// 1.5/ramp. Near a corner of an unlit gap, where two quad outlines cross inside
// the usable area, the split between the two projectors turns within a distance
// like the distance to that corner: steep, but continuous on the lit area.
double slope_bound(double deepest, double ramp) { return 2.0 / deepest + (ramp > 0.0 ? 3.0 / ramp : 0.0); }

// Continuity inside the lit union (the union's outline and the usable border are
// where the light really ends): nearby points have nearby weights.
TEST(BlendField, WeightsAreContinuous) {
  const auto group = keystoned_wall(1280, 800);
  std::mt19937 random(11);
  std::uniform_real_distribution<double> x(0.0, testing::kWallWidth);
  std::uniform_real_distribution<double> y(0.0, testing::kWallHeight);
  std::uniform_real_distribution<double> angle(0.0, 6.283185307179586);
  constexpr double kStep = 1e-6;
  for (double ramp : kRamps) {
    const BlendField field(group, wall_area(), ramp);
    double worst = 0.0;  // slope over its bound
    double steepest = 0.0;
    for (int k = 0; k < 200000; ++k) {
      const glm::dvec2 a(x(random), y(random));
      const double t = angle(random);
      const glm::dvec2 b = a + kStep * glm::dvec2(std::cos(t), std::sin(t));
      double deepest = 0.0;
      for (std::size_t i = 0; i < group.size(); ++i) {
        deepest = std::max(deepest, std::min(field.edge_distance(i, a), field.edge_distance(i, b)));
      }
      if (deepest < 100 * kStep || !wall_area().contains(a) || !wall_area().contains(b)) continue;
      for (std::size_t i = 0; i < group.size(); ++i) {
        const double slope = std::abs(field.weight(i, a) - field.weight(i, b)) / kStep;
        steepest = std::max(steepest, slope);
        worst = std::max(worst, slope / slope_bound(deepest - kStep, ramp));
      }
    }
    // A jump would show as a slope of ~1/kStep = 1e6 per metre.
    EXPECT_LE(worst, 1.0) << "ramp " << ramp;
    std::printf("ramp %.2f m: steepest weight slope %.1f /m, %.2f of its bound\n", ramp, steepest, worst);
  }
}

TEST(BlendWeights, ImageHoldsTheFieldAtPixelCentres) {
  const auto group = keystoned_wall(320, 200);
  for (double ramp : kRamps) {
    const BlendField field(group, wall_area(), ramp);
    for (std::size_t i = 0; i < group.size(); ++i) {
      const image::FloatImage weights = blend_weights(group, i, wall_area(), ramp);
      ASSERT_EQ(weights.width, 320);
      ASSERT_EQ(weights.height, 200);
      ASSERT_EQ(weights.channels, 1);
      for (int y = 0; y < weights.height; y += 7) {
        for (int x = 0; x < weights.width; x += 5) {
          const glm::dvec2 s = group[i].to_screen(glm::dvec2(x + 0.5, y + 0.5));
          EXPECT_NEAR(weights.at(x, y, 0), field.weight(i, s), 1e-6);
        }
      }
    }
  }
}

// Neighbouring pixels of a weight image differ little except across the mask's
// edge (the usable border), by no more than the slope bound over a pixel.
TEST(BlendWeights, NeighbouringPixelsHaveNoJumps) {
  const auto group = keystoned_wall(1280, 800);
  for (double ramp : kRamps) {
    const BlendField field(group, wall_area(), ramp);
    for (std::size_t i = 0; i < group.size(); ++i) {
      const image::FloatImage weights = blend_weights(field, group[i], i);
      double largest = 0.0;
      double worst = 0.0;  // jump over its bound
      for (int y = 0; y + 1 < weights.height; ++y) {
        for (int x = 0; x + 1 < weights.width; ++x) {
          // Pixels whose neighbourhood meets the usable border are masked: skip.
          bool near_border = false;
          for (const glm::dvec2 corner : {glm::dvec2(x - 1, y - 1), glm::dvec2(x + 2, y - 1), glm::dvec2(x + 2, y + 2),
                                          glm::dvec2(x - 1, y + 2)}) {
            near_border = near_border || !wall_area().contains(group[i].to_screen(corner));
          }
          if (near_border) continue;
          const glm::dvec2 s = group[i].to_screen(glm::dvec2(x + 0.5, y + 0.5));
          const double pixel = glm::length(group[i].to_screen(glm::dvec2(x + 1.5, y + 1.5)) - s);  // diagonal
          double deepest = 0.0;
          for (std::size_t j = 0; j < group.size(); ++j) deepest = std::max(deepest, field.edge_distance(j, s));
          const float w = weights.at(x, y, 0);
          const double jump = std::max(std::abs(w - weights.at(x + 1, y, 0)), std::abs(w - weights.at(x, y + 1, 0)));
          if (deepest > 0.05) largest = std::max(largest, jump);
          worst = std::max(worst, jump / (pixel * slope_bound(std::max(deepest - pixel, 1e-9), ramp)));
        }
      }
      EXPECT_LE(worst, 1.0) << "projector " << i << ", ramp " << ramp;
      // Away from gap corners the steps are small: the roll-off is spread out.
      EXPECT_LE(largest, ramp == 0.02 ? 0.15 : 0.05) << "projector " << i << ", ramp " << ramp;
      std::printf("projector %zu, ramp %.2f m: largest step %.4f (%.2f of its bound)\n", i, ramp, largest, worst);
    }
  }
}

TEST(BlendWeights, FullHdTakesWellUnderASecond) {
  const auto group = keystoned_wall(1920, 1080);
  const auto start = std::chrono::steady_clock::now();
  const image::FloatImage weights = blend_weights(group, 1, wall_area(), 0.0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("1920×1080 weights of one projector among 3: %.1f ms\n", seconds * 1e3);
  EXPECT_EQ(weights.width, 1920);
#ifdef NDEBUG
  EXPECT_LT(seconds, 0.5);
#endif
}

}  // namespace
}  // namespace optique::optics
