#pragma once
// Synthetic projectors for the calibration tests and benchmark: a physical
// pinhole model (intrinsics K, a pose in the screen frame) rather than random
// matrices, so that "oblique", "grazing" and "8K" mean what they say.
//
// Screen frame: the screen plane is z = 0, +z towards the viewer, y up. Camera
// frame: x right, y down (pixel rows), z along the optical axis. Then
// H = K · [r1 r2 t] with r1, r2 the first two columns of the rotation screen →
// camera and t = −R·C.

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "geometry/homography.h"

namespace optique::testing {

struct PinholeProjector {
  const char* name = "";
  int width = 1920;
  int height = 1080;
  double focal_px = 2000.0;        // square pixels
  glm::dvec2 principal{960, 540};  // the lens shift moves it
  glm::dvec3 position{0.0};        // metres, screen frame
  glm::dvec3 target{0.0};          // the screen point on the optical axis
  double roll_deg = 0.0;           // about the optical axis

  // Rows: the camera's x, y, z axes in the screen frame.
  [[nodiscard]] glm::dmat3 rotation() const {
    const glm::dvec3 z = glm::normalize(target - position);
    glm::dvec3 x = glm::normalize(glm::cross(z, glm::dvec3(0.0, 1.0, 0.0)));
    glm::dvec3 y = glm::cross(z, x);
    const double roll = roll_deg * std::numbers::pi / 180.0;
    const glm::dvec3 xr = std::cos(roll) * x + std::sin(roll) * y;
    y = -std::sin(roll) * x + std::cos(roll) * y;
    x = xr;
    glm::dmat3 r(0.0);
    for (int c = 0; c < 3; ++c) {
      r[c][0] = x[c];
      r[c][1] = y[c];
      r[c][2] = z[c];
    }
    return r;
  }

  [[nodiscard]] glm::dmat3 homography() const {
    const glm::dmat3 r = rotation();
    const glm::dvec3 t = -(r * position);
    glm::dmat3 k(1.0);
    k[0][0] = focal_px;
    k[1][1] = focal_px;
    k[2][0] = principal.x;
    k[2][1] = principal.y;
    glm::dmat3 rt(0.0);
    rt[0] = r[0];  // image of the screen's x axis
    rt[1] = r[1];  // and y axis
    rt[2] = t;
    const glm::dmat3 h = k * rt;
    return h / h[2][2];
  }

  // Angle between the optical axis and the screen normal, degrees.
  [[nodiscard]] double incidence_deg() const {
    const glm::dvec3 z = glm::normalize(target - position);
    return std::acos(std::abs(z.z)) * 180.0 / std::numbers::pi;
  }
};

// Front projectors on a 4 × 2.25 m wall, from mild to grazing, and one at 8K.
inline std::vector<PinholeProjector> projector_cases() {
  PinholeProjector mild{"mild keystone", 1920, 1080, 2900.0, {960, 540}, {2.0, 0.5, 3.5}, {2.0, 1.2, 0.0}, 0.0};
  PinholeProjector oblique{"strong oblique", 1920, 1080, 2400.0, {960, 540}, {-1.0, 0.6, 2.2}, {2.2, 1.1, 0.0}, 3.0};
  // 80° from the normal at the centre; a long-throw lens keeps the far edge at
  // about 86°, short of the horizon.
  const double grazing_angle = 80.0 * std::numbers::pi / 180.0;
  const glm::dvec3 centre(2.0, 1.1, 0.0);
  PinholeProjector grazing{
      "grazing 80°", 1920,       1080,
      9000.0,        {960, 540}, centre + 4.0 * glm::dvec3(-std::sin(grazing_angle), 0.0, std::cos(grazing_angle)),
      centre,        0.0};
  PinholeProjector k8{"8K", 7680, 4320, 11500.0, {3840, 2600}, {2.3, 0.9, 3.2}, {2.0, 1.1, 0.0}, 1.0};
  return {mild, oblique, grazing, k8};
}

// `columns` × `rows` pixels spread over the image (5 % margins), with their
// exact screen points.
inline std::vector<geometry::Correspondence> grid_points(const glm::dmat3& h, int width, int height, int columns,
                                                         int rows) {
  const glm::dmat3 inverse = glm::inverse(h);
  std::vector<geometry::Correspondence> points;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      const glm::dvec2 pixel(width * (0.05 + 0.9 * i / (columns - 1)), height * (0.05 + 0.9 * j / (rows - 1)));
      points.push_back({geometry::apply(inverse, pixel), pixel});
    }
  }
  return points;
}

// Adds N(0, σ²) to each pixel coordinate.
inline std::vector<geometry::Correspondence> with_pixel_noise(std::vector<geometry::Correspondence> points,
                                                              double sigma, std::mt19937_64& random) {
  std::normal_distribution<double> noise(0.0, sigma);
  for (auto& p : points) {
    const double dx = noise(random);
    const double dy = noise(random);
    p.pixel += glm::dvec2(dx, dy);
  }
  return points;
}

// RMS transfer error per coordinate, as Hartley & Zisserman's result 5.2 counts
// it: √(Σᵢ |Ĥ(sᵢ) − H(sᵢ)|² / 2n). The ML estimate's expected value is
// σ·√(d / 2n), d = 8, for noise in one image only.
inline double transfer_error(const glm::dmat3& estimate, const glm::dmat3& truth,
                             const std::vector<geometry::Correspondence>& points) {
  double sum = 0.0;
  for (const auto& p : points) {
    const glm::dvec2 d = geometry::apply(estimate, p.screen) - geometry::apply(truth, p.screen);
    sum += glm::dot(d, d);
  }
  return std::sqrt(sum / (2.0 * static_cast<double>(points.size())));
}

}  // namespace optique::testing
