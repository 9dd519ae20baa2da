#include "optics/blend.h"

#include <cassert>
#include <cmath>

#include <glm/geometric.hpp>

namespace optique::optics {
namespace {

double signed_area(const std::array<glm::dvec2, 4>& quad) {
  double twice = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const glm::dvec2& a = quad[i];
    const glm::dvec2& b = quad[(i + 1) % 4];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * twice;
}

}  // namespace

QuadDistance::QuadDistance(const std::array<glm::dvec2, 4>& quad) {
  // A homography may mirror the image, so the corners can run either way round:
  // the sign of the area says which side of each edge is inside.
  const double orientation = signed_area(quad) >= 0.0 ? 1.0 : -1.0;
  for (std::size_t i = 0; i < 4; ++i) {
    const glm::dvec2& a = quad[i];
    const glm::dvec2& b = quad[(i + 1) % 4];
    const glm::dvec2 along = b - a;
    const double length = glm::length(along);
    if (!(length > 0.0)) {
      // A collapsed edge bounds nothing; the other edges still do.
      edges_[i] = glm::dvec3(0.0, 0.0, INFINITY);
      continue;
    }
    const glm::dvec2 inward = orientation * glm::dvec2(-along.y, along.x) / length;
    edges_[i] = glm::dvec3(inward, -glm::dot(inward, a));
  }
}

double blend_rolloff(double distance, double ramp) {
  if (!(distance > 0.0)) return 0.0;
  if (ramp <= 0.0) return distance * distance;
  if (distance >= ramp) return 1.0;
  const double t = distance / ramp;
  return t * t * (3.0 - 2.0 * t);
}

BlendField::BlendField(std::span<const geometry::ProjectorGeometry> group, const geometry::ScreenRect& usable,
                       double ramp)
    : ramps_(group.size(), ramp), usable_(usable) {
  distances_.reserve(group.size());
  for (const geometry::ProjectorGeometry& g : group) distances_.emplace_back(g.lit_quad());
}

BlendField::BlendField(std::span<const geometry::ProjectorGeometry> group, const geometry::ScreenRect& usable,
                       std::span<const double> ramps)
    : ramps_(ramps.begin(), ramps.end()), usable_(usable) {
  assert(ramps.size() == group.size());
  distances_.reserve(group.size());
  for (const geometry::ProjectorGeometry& g : group) distances_.emplace_back(g.lit_quad());
}

double BlendField::weight(std::size_t self, const glm::dvec2& screen) const {
  assert(self < distances_.size());
  if (!usable_.contains(screen)) return 0.0;
  const double own_distance = distances_[self](screen);
  if (!(own_distance > 0.0)) return 0.0;
  double own = 0.0;
  double total = 0.0;
  double distance_sum = 0.0;
  for (std::size_t j = 0; j < distances_.size(); ++j) {
    const double d = j == self ? own_distance : distances_[j](screen);
    const double f = blend_rolloff(d, ramps_[j]);
    if (j == self) own = f;
    total += f;
    distance_sum += d;
  }
  if (total > 0.0) return own / total;
  // Every roll-off underflowed (points within ~1e-154 m of the edges): share by
  // distance, the same limit up to a factor near 1, rather than dropping the light.
  return own_distance / distance_sum;
}

bool BlendField::covered(const glm::dvec2& screen) const {
  if (!usable_.contains(screen)) return false;
  for (const QuadDistance& d : distances_) {
    if (d(screen) > 0.0) return true;
  }
  return false;
}

image::FloatImage blend_weights(const BlendField& field, const geometry::ProjectorGeometry& geometry,
                                std::size_t self) {
  image::FloatImage weights(geometry.width(), geometry.height(), 1);
  const glm::dmat3& to_screen = geometry.pixel_to_screen();
  for (int y = 0; y < geometry.height(); ++y) {
    // Homogeneous screen coordinates are affine along a row: step by H⁻¹'s first column.
    const glm::dvec3 row_start = to_screen * glm::dvec3(0.5, y + 0.5, 1.0);
    const glm::dvec3 step = to_screen[0];
    float* out = weights.pixels.data() + static_cast<std::size_t>(y) * geometry.width();
    for (int x = 0; x < geometry.width(); ++x) {
      const glm::dvec3 q = row_start + static_cast<double>(x) * step;
      out[x] = static_cast<float>(field.weight(self, glm::dvec2(q.x / q.z, q.y / q.z)));
    }
  }
  return weights;
}

image::FloatImage blend_weights(std::span<const geometry::ProjectorGeometry> group, std::size_t self,
                                const geometry::ScreenRect& usable, double ramp) {
  assert(self < group.size());
  return blend_weights(BlendField(group, usable, ramp), group[self], self);
}

double blend_weight(std::span<const geometry::ProjectorGeometry> group, std::size_t self,
                    const geometry::ScreenRect& usable, double ramp, const glm::dvec2& screen) {
  return BlendField(group, usable, ramp).weight(self, screen);
}

}  // namespace optique::optics
