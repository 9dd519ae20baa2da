// Accuracy against the noise-limited optimum: with σ = 0.5 px Gaussian noise on
// the pixels of 20 points, the maximum-likelihood H has an expected RMS transfer
// error of σ·√(d / 2n) = σ·√(8/40) per coordinate (Hartley & Zisserman, result
// 5.2, noise in one image only). The refined fit must get within 10 % of it on
// every projector; the DLT alone is printed beside it to show what the
// refinement adds.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "calib/fit.h"
#include "pinhole_projector.h"

namespace optique::calib {
namespace {

constexpr double kSigma = 0.5;
constexpr int kTrials = 250;

struct Accuracy {
  double dlt = 0.0;  // √(mean over trials of ε²)
  double refined = 0.0;
  double refined_mean = 0.0;  // mean over trials of ε
  double optimum = 0.0;
};

Accuracy measure(const testing::PinholeProjector& projector, std::uint64_t seed) {
  const glm::dmat3 truth = projector.homography();
  const auto exact = testing::grid_points(truth, projector.width, projector.height, 5, 4);
  std::mt19937_64 random(seed);
  Accuracy a;
  for (int t = 0; t < kTrials; ++t) {
    const auto noisy = testing::with_pixel_noise(exact, kSigma, random);
    FitOptions dlt_only;
    dlt_only.refine = false;
    auto dlt = fit_homography(noisy, dlt_only);
    auto refined = fit_homography(noisy);
    EXPECT_TRUE(dlt.ok() && refined.ok()) << projector.name;
    if (!dlt.ok() || !refined.ok()) return a;
    const double e_dlt = testing::transfer_error(dlt.value().homography, truth, exact);
    const double e_refined = testing::transfer_error(refined.value().homography, truth, exact);
    a.dlt += e_dlt * e_dlt;
    a.refined += e_refined * e_refined;
    a.refined_mean += e_refined;
  }
  a.dlt = std::sqrt(a.dlt / kTrials);
  a.refined = std::sqrt(a.refined / kTrials);
  a.refined_mean /= kTrials;
  a.optimum = kSigma * std::sqrt(8.0 / (2.0 * static_cast<double>(exact.size())));
  return a;
}

TEST(CalibrationAccuracy, RefinedFitReachesTheNoiseLimitedOptimum) {
  std::uint64_t seed = 11;
  std::printf("%-16s %9s %9s %12s %12s %14s\n", "projector", "incidence", "optimum", "DLT only", "refined",
              "refined (mean)");
  for (const auto& projector : testing::projector_cases()) {
    const Accuracy a = measure(projector, seed++);
    std::printf("%-16s %8.1f° %9.4f %7.4f %+4.0f%% %7.4f %+4.0f%% %9.4f\n", projector.name, projector.incidence_deg(),
                a.optimum, a.dlt, 100.0 * (a.dlt / a.optimum - 1.0), a.refined, 100.0 * (a.refined / a.optimum - 1.0),
                a.refined_mean);
    EXPECT_NEAR(a.refined, a.optimum, 0.1 * a.optimum) << projector.name;
    EXPECT_NEAR(a.refined_mean, a.optimum, 0.1 * a.optimum) << projector.name;
    EXPECT_LE(a.refined, a.dlt) << projector.name;
    // The DLT weights each point's error by its w: the more oblique the
    // projector, the further it falls short, and the refinement makes up for it.
    if (projector.incidence_deg() > 70.0) {
      EXPECT_GT(a.dlt, 1.1 * a.optimum) << projector.name;
    }
    if (projector.incidence_deg() > 45.0) {
      EXPECT_GT(a.dlt, 1.05 * a.optimum) << projector.name;
    }
  }
}

}  // namespace
}  // namespace optique::calib
