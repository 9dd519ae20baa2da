#include "optics/compose.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <vector>

#include <glm/vec2.hpp>

#include "image/convert.h"
#include "keystoned_wall.h"
#include "optics/blend.h"

namespace optique::optics {
namespace {

using testing::keystoned_wall;
using testing::kWallHeight;
using testing::kWallWidth;
using testing::wall_area;

using Pattern = std::function<glm::vec3(const glm::dvec2&)>;

glm::dvec2 output_centre(int u, int v, double ppm, double height) {
  return glm::dvec2((u + 0.5) / ppm, height - (v + 0.5) / ppm);
}

// What each projector emits to show `pattern`: the pattern at its pixel centres
// (mapped to the screen through H⁻¹) times its blend weight.
std::vector<image::FloatImage> projector_images(const std::vector<geometry::ProjectorGeometry>& group, double ramp,
                                                const Pattern& pattern) {
  std::vector<image::FloatImage> images;
  const BlendField field(group, wall_area(), ramp);
  for (std::size_t i = 0; i < group.size(); ++i) {
    const image::FloatImage weights = blend_weights(field, group[i], i);
    image::FloatImage emitted(group[i].width(), group[i].height(), 4);
    for (int y = 0; y < emitted.height; ++y) {
      for (int x = 0; x < emitted.width; ++x) {
        const glm::vec3 c = pattern(group[i].to_screen(glm::dvec2(x + 0.5, y + 0.5)));
        const float w = weights.at(x, y, 0);
        for (int k = 0; k < 3; ++k) emitted.at(x, y, k) = w * c[k];
        emitted.at(x, y, 3) = 1.0f;
      }
    }
    images.push_back(std::move(emitted));
  }
  return images;
}

image::FloatImage compose(const std::vector<geometry::ProjectorGeometry>& group,
                          const std::vector<image::FloatImage>& images, double ppm, int subsamples = 0) {
  std::vector<ProjectedImage> projected;
  for (std::size_t i = 0; i < group.size(); ++i) projected.push_back({&group[i], &images[i]});
  ComposeOptions options;
  options.pixels_per_metre = ppm;
  options.subsamples = subsamples;
  return compose_screen(projected, kWallWidth, kWallHeight, options);
}

// The pattern rasterized directly at the screen's pixels: the average over each
// pixel's footprint (what the composite approximates), by n × n samples.
image::FloatImage rasterize(const Pattern& pattern, double ppm, int n) {
  image::FloatImage out(screen_pixels(kWallWidth, ppm), screen_pixels(kWallHeight, ppm), 4);
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      glm::dvec3 sum(0.0);
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          sum += glm::dvec3(pattern(glm::dvec2((u + (i + 0.5) / n) / ppm, kWallHeight - (v + (j + 0.5) / n) / ppm)));
        }
      }
      for (int k = 0; k < 3; ++k) out.at(u, v, k) = static_cast<float>(sum[k] / (n * n));
      out.at(u, v, 3) = 1.0f;
    }
  }
  return out;
}

// Where two lit quads' outlines cross inside the usable area: the corners of an
// unlit gap (the fixture has one at the bottom, near x = 1.78 m).
std::vector<glm::dvec2> outline_crossings(const std::vector<geometry::ProjectorGeometry>& group) {
  std::vector<glm::dvec2> found;
  for (std::size_t i = 0; i < group.size(); ++i) {
    for (std::size_t j = i + 1; j < group.size(); ++j) {
      const auto a = group[i].lit_quad();
      const auto b = group[j].lit_quad();
      for (std::size_t e = 0; e < 4; ++e) {
        for (std::size_t f = 0; f < 4; ++f) {
          const glm::dvec2 p = a[e];
          const glm::dvec2 r = a[(e + 1) % 4] - p;
          const glm::dvec2 q = b[f];
          const glm::dvec2 s = b[(f + 1) % 4] - q;
          const double den = r.x * s.y - r.y * s.x;
          if (den == 0.0) continue;
          const double t = ((q.x - p.x) * s.y - (q.y - p.y) * s.x) / den;
          const double u = ((q.x - p.x) * r.y - (q.y - p.y) * r.x) / den;
          const glm::dvec2 x = p + t * r;
          if (t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0 && wall_area().contains(x)) found.push_back(x);
        }
      }
    }
  }
  return found;
}

// Pixels where the composite is fully defined: one pixel in from the usable
// border, and the pixel's footprint (plus a projector pixel) inside the lit union.
// Near a gap corner the weights turn within about the distance to the corner (see
// optics/blend.h), faster than a projector's pixel grid can follow, so the sum of
// interpolated weights strays from 1 there: `corner_margin` metres around such
// corners are left out.
std::vector<bool> well_covered(const std::vector<geometry::ProjectorGeometry>& group, double ppm,
                               double corner_margin) {
  const int width = screen_pixels(kWallWidth, ppm);
  const int height = screen_pixels(kWallHeight, ppm);
  const BlendField field(group, wall_area(), 0.0);
  const auto corners = outline_crossings(group);
  std::vector<bool> mask(static_cast<std::size_t>(width) * height, false);
  for (int v = 1; v + 1 < height; ++v) {
    for (int u = 1; u + 1 < width; ++u) {
      const glm::dvec2 s = output_centre(u, v, ppm, kWallHeight);
      double deepest = 0.0;
      for (std::size_t i = 0; i < group.size(); ++i) deepest = std::max(deepest, field.edge_distance(i, s));
      bool near_corner = false;
      for (const glm::dvec2& c : corners) near_corner = near_corner || glm::length(s - c) < corner_margin;
      mask[static_cast<std::size_t>(v) * width + u] = deepest > 1.5 / ppm && !near_corner;
    }
  }
  return mask;
}

// PSNR of RGB over the masked pixels, peak 1.
double masked_psnr(const image::FloatImage& a, const image::FloatImage& b, const std::vector<bool>& mask) {
  double sum = 0.0;
  std::size_t count = 0;
  for (int v = 0; v < a.height; ++v) {
    for (int u = 0; u < a.width; ++u) {
      if (!mask[static_cast<std::size_t>(v) * a.width + u]) continue;
      for (int k = 0; k < 3; ++k) {
        const double d = a.at(u, v, k) - b.at(u, v, k);
        sum += d * d;
      }
      count += 3;
    }
  }
  return 10.0 * std::log10(1.0 / std::max(sum / static_cast<double>(count), 1e-30));
}

TEST(ScreenSize, MatchesRenderReference) {
  EXPECT_EQ(screen_pixels(3.0, 200.0), 600);
  EXPECT_EQ(screen_pixels(2.25, 160.0), 360);
  EXPECT_EQ(screen_pixels(1.0025, 200.0), 201);  // rounds half away from zero
  const image::FloatImage black = compose_screen({}, 3.0, 1.0, ComposeOptions{200.0, 0});
  EXPECT_EQ(black.width, 600);
  EXPECT_EQ(black.height, 200);
  EXPECT_EQ(black.channels, 4);
  EXPECT_EQ(black.at(10, 10, 0), 0.0f);
  EXPECT_EQ(black.at(10, 10, 3), 1.0f);
}

TEST(Subsamples, FollowTheProjectorsPixelDensity) {
  const auto aligned = geometry::ProjectorGeometry::make(
                           geometry::aligned_homography({glm::dvec2(0.0), glm::dvec2(3.0, 1.0)}, 300, 100), 300, 100)
                           .value();
  EXPECT_EQ(subsamples_for(aligned, 100.0), 2);
  EXPECT_EQ(subsamples_for(aligned, 400.0), 1);
  EXPECT_EQ(subsamples_for(aligned, 10.0), 16);
  const auto group = keystoned_wall(1280, 800);
  EXPECT_GE(subsamples_for(group[0], 200.0), 11);  // ~1100 px/m at its densest corner
}

// An aligned projector whose pixels are exactly the output's: one subsample at
// each output pixel centre lands on a projector pixel centre, so the composite is
// the image itself. Any half-pixel or flipped-axis slip breaks this.
TEST(ComposeScreen, AlignedProjectorWithTheScreensPixelsGivesTheImageBack) {
  const auto geometry =
      geometry::ProjectorGeometry::make(
          geometry::aligned_homography({glm::dvec2(0.0), glm::dvec2(kWallWidth, kWallHeight)}, 300, 100), 300, 100)
          .value();
  image::FloatImage image(300, 100, 3);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 300; ++x) {
      image.at(x, y, 0) = static_cast<float>(x) / 300.0f;
      image.at(x, y, 1) = static_cast<float>(y) / 100.0f;
      image.at(x, y, 2) = static_cast<float>((x * 7 + y * 13) % 17) / 17.0f;
    }
  }
  const ProjectedImage projected[] = {{&geometry, &image}};
  const image::FloatImage out = compose_screen(projected, kWallWidth, kWallHeight, ComposeOptions{100.0, 1});
  ASSERT_EQ(out.width, 300);
  ASSERT_EQ(out.height, 100);
  for (int y = 0; y < 100; ++y) {
    for (int x = 0; x < 300; ++x) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(out.at(x, y, k), image.at(x, y, k), 1e-6) << x << ", " << y;
      ASSERT_EQ(out.at(x, y, 3), 1.0f);
    }
  }
}

// A small blob in a keystoned projector lands where H⁻¹ says, to a few
// hundredths of an output pixel, and keeps its light (the composite integrates).
TEST(ComposeScreen, BlobLandsWhereTheHomographySays) {
  const auto group = keystoned_wall(1280, 800);
  const geometry::ProjectorGeometry& g = group[0];
  const glm::dvec2 centre(640.3, 400.7);
  image::FloatImage image(1280, 800, 4);
  for (int y = 0; y < 800; ++y) {
    for (int x = 0; x < 1280; ++x) {
      const glm::dvec2 d = glm::dvec2(x + 0.5, y + 0.5) - centre;
      image.at(x, y, 0) = image.at(x, y, 1) = image.at(x, y, 2) =
          static_cast<float>(std::exp(-glm::dot(d, d) / (2.0 * 2.0 * 2.0)));
    }
  }
  constexpr double kPpm = 400.0;
  const ProjectedImage projected[] = {{&g, &image}};
  const image::FloatImage out = compose_screen(projected, kWallWidth, kWallHeight, ComposeOptions{kPpm, 0});
  glm::dvec2 moment(0.0);
  double mass = 0.0;
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      const double value = out.at(u, v, 0);
      moment += value * glm::dvec2(u + 0.5, v + 0.5);
      mass += value;
    }
  }
  const glm::dvec2 expected_screen = g.to_screen(centre);
  const glm::dvec2 expected(expected_screen.x * kPpm, (kWallHeight - expected_screen.y) * kPpm);
  const glm::dvec2 found = moment / mass;
  std::printf("blob centroid off by (%.4f, %.4f) output px\n", found.x - expected.x, found.y - expected.y);
  EXPECT_NEAR(found.x, expected.x, 0.02);
  EXPECT_NEAR(found.y, expected.y, 0.02);
}

TEST(ComposeScreen, UniformLightTimesBlendWeightsAddsUpToOne) {
  const auto group = keystoned_wall(1280, 800);
  constexpr double kPpm = 200.0;
  ASSERT_EQ(outline_crossings(group).size(), 1u);
  const auto mask = well_covered(group, kPpm, 0.02);
  const auto near_corners = well_covered(group, kPpm, 0.0);
  for (double ramp : {0.0, 0.05, 0.2}) {
    const auto images = projector_images(group, ramp, [](const glm::dvec2&) { return glm::vec3(1.0f); });
    const auto start = std::chrono::steady_clock::now();
    const image::FloatImage out = compose(group, images, kPpm);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double worst = 0.0;
    double worst_near_corner = 0.0;
    glm::ivec2 where(0);
    std::size_t checked = 0;
    for (int v = 0; v < out.height; ++v) {
      for (int u = 0; u < out.width; ++u) {
        const std::size_t index = static_cast<std::size_t>(v) * out.width + u;
        if (near_corners[index]) worst_near_corner = std::max(worst_near_corner, std::abs(out.at(u, v, 0) - 1.0));
        if (!mask[index]) continue;
        ++checked;
        for (int k = 0; k < 3; ++k) {
          if (std::abs(out.at(u, v, k) - 1.0) > worst) {
            worst = std::abs(out.at(u, v, k) - 1.0);
            where = glm::ivec2(u, v);
          }
        }
      }
    }
    std::printf(
        "ramp %.2f m: uniform composite |v − 1| ≤ %.2e (at %d, %d) over %zu px, %.2e within 2 cm of the gap "
        "corner (compose %.0f ms)\n",
        ramp, worst, where.x, where.y, checked, worst_near_corner, seconds * 1e3);
    EXPECT_LE(worst_near_corner, 5e-3) << "ramp " << ramp;
    EXPECT_LE(worst, 1e-3) << "ramp " << ramp;
    EXPECT_GT(checked, static_cast<std::size_t>(0.9 * out.width * out.height));
  }
  // The gap at the bottom stays dark.
  const auto images = projector_images(group, 0.0, [](const glm::dvec2&) { return glm::vec3(1.0f); });
  const image::FloatImage out = compose(group, images, kPpm);
  EXPECT_EQ(out.at(static_cast<int>(1.7 * kPpm), out.height - 1, 0), 0.0f);
}

TEST(ComposeScreen, SmoothPatternMatchesTheDirectRaster) {
  const auto group = keystoned_wall(1920, 1200);
  constexpr double kPpm = 200.0;
  const Pattern smooth = [](const glm::dvec2& s) {
    constexpr double kTau = 6.283185307179586;
    return glm::vec3(0.5 + 0.4 * std::sin(kTau * s.x / 0.37 + 0.3) * std::cos(kTau * s.y / 0.29),
                     0.5 + 0.3 * std::cos(kTau * (s.x + s.y) / 0.53), 0.2 + 0.6 * s.x / kWallWidth);
  };
  const auto mask = well_covered(group, kPpm, 0.02);
  const image::FloatImage reference = rasterize(smooth, kPpm, 4);  // smooth: the midpoint rule errs by ~1e-5
  for (double ramp : {0.0, 0.05}) {
    const image::FloatImage out = compose(group, projector_images(group, ramp, smooth), kPpm);
    const double psnr = masked_psnr(out, reference, mask);
    std::printf("smooth pattern, ramp %.2f m: PSNR %.1f dB\n", ramp, psnr);
    EXPECT_GE(psnr, 50.0) << "ramp " << ramp;
  }
}

// Sub-pixel positions where a row (or column) of `image` crosses ½ between
// neighbouring masked pixels, in output pixel units along the line.
std::vector<double> crossings(const image::FloatImage& image, const std::vector<bool>& mask, int line, bool rows) {
  std::vector<double> found;
  const int length = rows ? image.width : image.height;
  auto value = [&](int i) { return rows ? image.at(i, line, 0) : image.at(line, i, 0); };
  auto masked = [&](int i) {
    return mask[rows ? static_cast<std::size_t>(line) * image.width + i
                     : static_cast<std::size_t>(i) * image.width + line];
  };
  for (int i = 0; i + 1 < length; ++i) {
    if (!masked(i) || !masked(i + 1)) continue;
    const double a = value(i) - 0.5;
    const double b = value(i + 1) - 0.5;
    if (a * b < 0.0 || (a == 0.0 && b != 0.0)) found.push_back(i + 0.5 + a / (a - b));
  }
  return found;
}

TEST(ComposeScreen, CheckerboardMatchesTheDirectRasterAndKeepsItsEdges) {
  const auto group = keystoned_wall(1920, 1200);
  constexpr double kPpm = 200.0;
  constexpr double kSquare = 0.1;
  constexpr double kPhase = 0.0137;  // edges fall inside output pixels, not on their borders
  const Pattern checkerboard = [](const glm::dvec2& s) {
    const auto i = static_cast<long>(std::floor((s.x - kPhase) / kSquare));
    const auto j = static_cast<long>(std::floor((s.y - kPhase) / kSquare));
    return glm::vec3((i + j) % 2 == 0 ? 0.9f : 0.1f);
  };
  const auto mask = well_covered(group, kPpm, 0.02);
  const image::FloatImage reference = rasterize(checkerboard, kPpm, 16);
  const image::FloatImage out = compose(group, projector_images(group, 0.0, checkerboard), kPpm);
  const double psnr = masked_psnr(out, reference, mask);
  std::printf("checkerboard (10 cm): PSNR %.1f dB\n", psnr);
  EXPECT_GE(psnr, 35.0);

  // Edge positions: along rows (vertical edges) and columns (horizontal edges),
  // away from the squares' corners where a line runs along an edge.
  double worst = 0.0;
  std::size_t edges = 0;
  for (bool rows : {true, false}) {
    const int lines = rows ? out.height : out.width;
    for (int line = 0; line < lines; ++line) {
      const double across = rows ? kWallHeight - (line + 0.5) / kPpm : (line + 0.5) / kPpm;
      const double to_edge = std::remainder(across - kPhase, kSquare);
      if (std::abs(to_edge) * kPpm < 2.0) continue;
      const auto want = crossings(reference, mask, line, rows);
      const auto got = crossings(out, mask, line, rows);
      for (double w : want) {
        double nearest = INFINITY;
        for (double g : got) nearest = std::min(nearest, std::abs(g - w));
        worst = std::max(worst, nearest);
        ++edges;
      }
      EXPECT_EQ(want.size(), got.size()) << (rows ? "row " : "column ") << line;
    }
  }
  std::printf("checkerboard: %zu edge crossings, worst offset %.3f px\n", edges, worst);
  EXPECT_GT(edges, 1000u);
  EXPECT_LE(worst, 0.5);
}

TEST(EncodeSrgb, IsTheRenderersTransferFunction) {
  image::FloatImage linear(5, 1, 4);
  const float values[] = {0.0f, 1.0f, 0.5f, 0.002f, 7.0f};
  for (int x = 0; x < 5; ++x) {
    for (int k = 0; k < 3; ++k) linear.at(x, 0, k) = values[x];
    linear.at(x, 0, 3) = 0.25f;
  }
  const image::ByteImage encoded = image::encode_srgb(linear);
  ASSERT_EQ(encoded.channels, 4);
  EXPECT_EQ(encoded.at(0, 0, 0), 0);
  EXPECT_EQ(encoded.at(1, 0, 0), 255);
  EXPECT_EQ(encoded.at(2, 0, 1), 188);                               // 1.055 · 0.5^(1/2.4) − 0.055 = 0.7354
  EXPECT_EQ(encoded.at(3, 0, 2), std::lround(0.002 * 12.92 * 255));  // linear toe
  EXPECT_EQ(encoded.at(4, 0, 0), 255);                               // clamped
  EXPECT_EQ(encoded.at(2, 0, 3), 255);                               // opaque, like the encoding pass
}

TEST(BoxDownsample, AveragesBlocks) {
  image::FloatImage image(4, 2, 1);
  const float values[] = {1, 2, 3, 4, 5, 6, 7, 8};
  std::copy(std::begin(values), std::end(values), image.pixels.begin());
  const image::FloatImage half = image::box_downsample(image, 2);
  ASSERT_EQ(half.width, 2);
  ASSERT_EQ(half.height, 1);
  EXPECT_FLOAT_EQ(half.at(0, 0, 0), (1 + 2 + 5 + 6) / 4.0f);
  EXPECT_FLOAT_EQ(half.at(1, 0, 0), (3 + 4 + 7 + 8) / 4.0f);
  EXPECT_EQ(image::box_downsample(image, 1).pixels, image.pixels);
}

}  // namespace
}  // namespace optique::optics
