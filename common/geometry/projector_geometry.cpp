#include "geometry/projector_geometry.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "geometry/homography.h"
#include "util/finite.h"

namespace optique::geometry {
namespace {

using geometry::apply;

std::array<glm::dvec2, 4> pixel_corners(int width, int height) {
  const double w = width;
  const double h = height;
  return {glm::dvec2(0.0, 0.0), glm::dvec2(w, 0.0), glm::dvec2(w, h), glm::dvec2(0.0, h)};
}

// Screen → NDC of R (x and y to [−1, 1]).
glm::dmat3 screen_to_user_ndc(const ScreenRect& r) {
  glm::dmat3 m(1.0);
  m[0][0] = 2.0 / r.width();
  m[1][1] = 2.0 / r.height();
  m[2][0] = -2.0 * r.min.x / r.width() - 1.0;
  m[2][1] = -2.0 * r.min.y / r.height() - 1.0;
  return m;
}

glm::dmat3 pixel_to_ndc_matrix(int width, int height) {
  glm::dmat3 m(1.0);
  m[0][0] = 2.0 / width;
  m[1][1] = -2.0 / height;
  m[2][0] = -1.0;
  m[2][1] = 1.0;
  return m;
}

// The part of a convex polygon inside a rectangle (Sutherland–Hodgman, one
// rectangle side at a time).
std::vector<glm::dvec2> clip_to(const std::vector<glm::dvec2>& polygon, const ScreenRect& rect) {
  std::vector<glm::dvec2> result = polygon;
  for (int side = 0; side < 4 && !result.empty(); ++side) {
    const int axis = side % 2;
    const bool keep_above = side < 2;  // min sides keep what is above them
    const double bound = keep_above ? rect.min[axis] : rect.max[axis];
    if (!std::isfinite(bound)) continue;
    auto inside = [&](const glm::dvec2& p) { return keep_above ? p[axis] >= bound : p[axis] <= bound; };
    std::vector<glm::dvec2> next;
    for (std::size_t i = 0; i < result.size(); ++i) {
      const glm::dvec2& a = result[i];
      const glm::dvec2& b = result[(i + 1) % result.size()];
      if (inside(a)) next.push_back(a);
      if (inside(a) != inside(b)) next.push_back(a + (b - a) * ((bound - a[axis]) / (b[axis] - a[axis])));
    }
    result = std::move(next);
  }
  return result;
}

}  // namespace

glm::dmat3 homography_from_rows(std::span<const double, 9> rows) {
  glm::dmat3 m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[c][r] = rows[static_cast<std::size_t>(r * 3 + c)];
  }
  return m;
}

std::array<double, 9> homography_rows(const glm::dmat3& homography) {
  std::array<double, 9> rows{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rows[static_cast<std::size_t>(r * 3 + c)] = homography[c][r];
  }
  return rows;
}

glm::dmat3 aligned_homography(const ScreenRect& region, int width, int height) {
  glm::dmat3 m(1.0);
  m[0][0] = width / region.width();
  m[2][0] = -region.min.x * width / region.width();
  m[1][1] = -height / region.height();
  m[2][1] = height + region.min.y * height / region.height();
  return m;
}

ProjectorGeometry::ProjectorGeometry(const glm::dmat3& screen_to_pixel, const glm::dmat3& pixel_to_screen, int width,
                                     int height)
    : screen_to_pixel_(screen_to_pixel), pixel_to_screen_(pixel_to_screen), width_(width), height_(height) {}

Result<ProjectorGeometry> ProjectorGeometry::make(const glm::dmat3& screen_to_pixel, int width, int height) {
  if (width <= 0 || height <= 0) return Error{"the projector has no pixels"};
  if (!util::finite(screen_to_pixel)) return Error{"the homography has a non-finite entry"};
  double scale = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) scale = std::max(scale, std::abs(screen_to_pixel[c][r]));
  }
  if (scale == 0.0) return Error{"the homography is all zeros"};
  const glm::dmat3 normalized = screen_to_pixel / scale;
  const glm::dmat3 inverse = glm::inverse(normalized);
  if (std::abs(glm::determinant(normalized)) < 1e-14 || !util::finite(inverse)) {
    return Error{"the homography is singular: it does not map the screen plane onto the image"};
  }
  // w of H⁻¹ is affine over the image, so its corners bound its sign.
  double w_min = INFINITY;
  double w_max = -INFINITY;
  for (const glm::dvec2& corner : pixel_corners(width, height)) {
    const double w = (inverse * glm::dvec3(corner, 1.0)).z;
    w_min = std::min(w_min, w);
    w_max = std::max(w_max, w);
  }
  const double largest = std::max(std::abs(w_min), std::abs(w_max));
  if (!(w_min * w_max > 0.0) || std::min(std::abs(w_min), std::abs(w_max)) < 1e-9 * largest) {
    return Error{
        "the screen plane's horizon crosses the projector's image: part of the image would land at "
        "infinity (is the homography screen → pixels, not the inverse?)"};
  }
  return ProjectorGeometry(screen_to_pixel, glm::inverse(screen_to_pixel), width, height);
}

glm::dvec2 ProjectorGeometry::to_pixel(const glm::dvec2& screen) const { return apply(screen_to_pixel_, screen); }
glm::dvec2 ProjectorGeometry::to_screen(const glm::dvec2& pixel) const { return apply(pixel_to_screen_, pixel); }

std::array<glm::dvec2, 4> ProjectorGeometry::lit_quad() const {
  std::array<glm::dvec2, 4> quad{};
  const auto corners = pixel_corners(width_, height_);
  for (std::size_t i = 0; i < 4; ++i) quad[i] = to_screen(corners[i]);
  return quad;
}

double ProjectorGeometry::max_pixels_per_metre() const {
  const glm::dmat3& h = screen_to_pixel_;
  double densest = 0.0;
  for (const glm::dvec2& screen : lit_quad()) {
    const glm::dvec3 q = h * glm::dvec3(screen, 1.0);
    const glm::dvec2 p = glm::dvec2(q) / q.z;
    // d(pixel)/d(screen) of p = (H·s)_xy / (H·s)_z.
    const double j00 = (h[0][0] - p.x * h[0][2]) / q.z;
    const double j01 = (h[1][0] - p.x * h[1][2]) / q.z;
    const double j10 = (h[0][1] - p.y * h[0][2]) / q.z;
    const double j11 = (h[1][1] - p.y * h[1][2]) / q.z;
    // Largest singular value of the 2×2 Jacobian.
    const double a = j00 * j00 + j10 * j10;
    const double b = j00 * j01 + j10 * j11;
    const double d = j01 * j01 + j11 * j11;
    const double largest = 0.5 * (a + d) + std::sqrt(0.25 * (a - d) * (a - d) + b * b);
    densest = std::max(densest, std::sqrt(largest));
  }
  return densest;
}

glm::dmat4 ObliqueProjection::matrix() const {
  const glm::dmat3& a = user_to_projector;  // a[column][row]
  glm::dmat4 m(0.0);
  m[0][0] = a[0][0];
  m[1][0] = a[1][0];
  m[3][0] = a[2][0];
  m[0][1] = a[0][1];
  m[1][1] = a[1][1];
  m[3][1] = a[2][1];
  m[2][2] = depth_scale;
  m[0][3] = a[0][2];
  m[1][3] = a[1][2];
  m[3][3] = a[2][2];
  return m;
}

glm::dvec2 ObliqueProjection::user_ndc(const glm::dvec2& screen) const {
  return apply(screen_to_user_ndc(bounds), screen);
}

glm::dvec2 ObliqueProjection::projector_ndc_to_user(const glm::dvec2& projector_ndc) const {
  return apply(glm::inverse(user_to_projector), projector_ndc);
}

Result<ObliqueProjection> oblique_projection(const ProjectorGeometry& geometry, const ScreenRect& usable) {
  const auto quad = geometry.lit_quad();
  ScreenRect bounds{quad[0], quad[0]};
  for (const glm::dvec2& p : quad) {
    bounds.min = glm::min(bounds.min, p);
    bounds.max = glm::max(bounds.max, p);
  }
  bounds.min = glm::max(bounds.min, usable.min);
  bounds.max = glm::min(bounds.max, usable.max);
  if (!(bounds.width() > 0.0 && bounds.height() > 0.0)) {
    return Error{"the projector's image misses the screen's usable area"};
  }
  const glm::dmat3 to_user = screen_to_user_ndc(bounds);
  glm::dmat3 a =
      pixel_to_ndc_matrix(geometry.width(), geometry.height()) * geometry.screen_to_pixel() * glm::inverse(to_user);
  // w over the image is affine in user NDC, so the corners of what is shown (the
  // lit quad within the usable area) bound it. Outside that the projector is
  // masked, and depth may clip there.
  const std::vector<glm::dvec2> shown = clip_to(std::vector<glm::dvec2>(quad.begin(), quad.end()), usable);
  double w_min = INFINITY;
  double w_max = -INFINITY;
  for (const glm::dvec2& corner : shown) {
    const glm::dvec2 u = apply(to_user, corner);
    const double w = a[0][2] * u.x + a[1][2] * u.y + a[2][2];
    w_min = std::min(w_min, w);
    w_max = std::max(w_max, w);
  }
  if (w_max < 0.0) {
    a = -a;
    std::swap(w_min, w_max);
    w_min = -w_min;
    w_max = -w_max;
  }
  if (!(w_min > 0.0) || !std::isfinite(w_max)) {
    return Error{"the projector's image reaches its horizon line (w ≤ 0 at a corner)"};
  }
  ObliqueProjection projection;
  projection.bounds = bounds;
  projection.user_to_projector = a / w_max;
  projection.depth_scale = w_min / w_max;
  return projection;
}

}  // namespace optique::geometry
