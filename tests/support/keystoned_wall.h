#pragma once
// Test fixture shared by the optics tests: three visibly keystoned projectors on a
// 3 m × 1 m wall, neighbours overlapping by about 20 %, overshooting the top and
// bottom edges, and leaving a gap at the bottom between the first and the third
// (the middle one's lower right corner is above the screen's bottom edge).

#include <array>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec2.hpp>

#include "geometry/projector_geometry.h"

namespace optique::testing {

// The homography that sends the projector's pixel corners (top-left, top-right,
// bottom-right, bottom-left) to `quad` on the screen: Heckbert's square → quad map
// after pixels → unit square, inverted (H is screen → pixels).
inline glm::dmat3 homography_onto(const std::array<glm::dvec2, 4>& quad, int width, int height) {
  const glm::dvec2 p0 = quad[0];  // (0, 0) of the unit square
  const glm::dvec2 p1 = quad[1];  // (1, 0)
  const glm::dvec2 p2 = quad[2];  // (1, 1)
  const glm::dvec2 p3 = quad[3];  // (0, 1)
  const glm::dvec2 s = p0 - p1 + p2 - p3;
  const glm::dvec2 d1 = p1 - p2;
  const glm::dvec2 d2 = p3 - p2;
  const double den = d1.x * d2.y - d2.x * d1.y;
  const double g = (s.x * d2.y - d2.x * s.y) / den;
  const double h = (d1.x * s.y - s.x * d1.y) / den;
  glm::dmat3 square_to_quad;  // [col][row]
  square_to_quad[0] = glm::dvec3(p1.x - p0.x + g * p1.x, p1.y - p0.y + g * p1.y, g);
  square_to_quad[1] = glm::dvec3(p3.x - p0.x + h * p3.x, p3.y - p0.y + h * p3.y, h);
  square_to_quad[2] = glm::dvec3(p0.x, p0.y, 1.0);
  glm::dmat3 pixels_to_square(1.0);
  pixels_to_square[0][0] = 1.0 / width;
  pixels_to_square[1][1] = 1.0 / height;
  return glm::inverse(square_to_quad * pixels_to_square);
}

inline constexpr double kWallWidth = 3.0;
inline constexpr double kWallHeight = 1.0;

inline std::vector<std::array<glm::dvec2, 4>> keystoned_quads() {
  return {
      {glm::dvec2(-0.08, 1.06), glm::dvec2(1.22, 1.14), glm::dvec2(1.18, -0.12), glm::dvec2(-0.05, -0.04)},
      {glm::dvec2(0.93, 1.08), glm::dvec2(2.08, 1.03), glm::dvec2(2.12, 0.10), glm::dvec2(0.97, -0.09)},
      {glm::dvec2(1.80, 1.15), glm::dvec2(3.06, 1.04), glm::dvec2(3.10, -0.03), glm::dvec2(1.78, -0.12)},
  };
}

inline std::vector<geometry::ProjectorGeometry> keystoned_wall(int width, int height) {
  std::vector<geometry::ProjectorGeometry> group;
  for (const auto& quad : keystoned_quads()) {
    group.push_back(geometry::ProjectorGeometry::make(homography_onto(quad, width, height), width, height).value());
  }
  return group;
}

inline geometry::ScreenRect wall_area() { return {glm::dvec2(0.0), glm::dvec2(kWallWidth, kWallHeight)}; }

}  // namespace optique::testing
