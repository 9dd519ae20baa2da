#pragma once
// Intensity roll-off across overlapping projectors (Raskar, "Immersive Planar
// Display using Roughly Aligned Projectors"; docs/design.md, "Overlap"): each
// projector of a group (the projectors that light one screen for one eye) scales
// its light by a weight, and the weights of the group sum to 1 at every point of
// the usable area that at least one projector lights. Outside the usable area
// every weight is 0: the mask (the paper's black polygon).
//
// Weight of projector i at screen point s: w_i = f_i(d_i(s)) / Σ_j f_j(d_j(s)),
// where d_j is the distance in metres from s to the nearest edge of projector j's
// lit quad (0 outside it) and f_j the roll-off: smoothstep(0, ramp_j, d) when
// ramp_j > 0, d² when ramp_j = 0 (ramps across the whole overlap). Both are C1 in
// d, and d is continuous, so the weights are continuous wherever the sum is not 0:
// on the whole lit part of the usable area. The one place they are steep is next
// to a corner of an unlit gap, where two quads' outlines cross inside the usable
// area: there both distances vanish and the split between the two projectors
// turns within about the distance to that corner (the light still sums to 1).
// Every node of a group must use the same ramps, or the sum is not 1.

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "geometry/projector_geometry.h"
#include "image/image.h"

namespace optique::optics {

// Distance from a screen point to the boundary of a projector's lit quad, from
// the quad's four edge lines, precomputed: for a point inside a convex polygon
// the nearest boundary point lies on the nearest edge line.
class QuadDistance {
 public:
  explicit QuadDistance(const std::array<glm::dvec2, 4>& quad);

  // Metres to the nearest edge; 0 on and outside the quad.
  [[nodiscard]] double operator()(const glm::dvec2& screen) const {
    double d = edges_[0].x * screen.x + edges_[0].y * screen.y + edges_[0].z;
    for (std::size_t e = 1; e < 4; ++e) {
      const double de = edges_[e].x * screen.x + edges_[e].y * screen.y + edges_[e].z;
      d = de < d ? de : d;
    }
    return d > 0.0 ? d : 0.0;
  }

 private:
  // Per edge: inward unit normal (x, y) and offset z, so that n·s + z is the
  // signed distance, positive inside.
  std::array<glm::dvec3, 4> edges_{};
};

// The roll-off f: smoothstep(0, ramp, d) for ramp > 0, d² for ramp = 0.
[[nodiscard]] double blend_rolloff(double distance, double ramp);

// The weights of one group, evaluated anywhere on the screen.
class BlendField {
 public:
  // One ramp for every projector of the group (metres, 0 = default d²).
  BlendField(std::span<const geometry::ProjectorGeometry> group, const geometry::ScreenRect& usable, double ramp);
  // One ramp per projector (`ramps.size() == group.size()`).
  BlendField(std::span<const geometry::ProjectorGeometry> group, const geometry::ScreenRect& usable,
             std::span<const double> ramps);

  [[nodiscard]] std::size_t size() const { return distances_.size(); }
  // Weight of projector `self` at screen point `screen` (metres, screen frame).
  [[nodiscard]] double weight(std::size_t self, const glm::dvec2& screen) const;
  // Distance from `screen` to projector `index`'s nearest quad edge (0 outside).
  [[nodiscard]] double edge_distance(std::size_t index, const glm::dvec2& screen) const {
    return distances_[index](screen);
  }
  // True when some projector of the group lights `screen` and it is usable.
  [[nodiscard]] bool covered(const glm::dvec2& screen) const;

 private:
  std::vector<QuadDistance> distances_;
  std::vector<double> ramps_;
  geometry::ScreenRect usable_;
};

// The weight image of projector `self` of `group`: one channel, the projector's
// width × height, evaluated at its pixel centres s = H⁻¹(x + ½, y + ½).
[[nodiscard]] image::FloatImage blend_weights(std::span<const geometry::ProjectorGeometry> group, std::size_t self,
                                              const geometry::ScreenRect& usable, double ramp);
[[nodiscard]] image::FloatImage blend_weights(const BlendField& field, const geometry::ProjectorGeometry& geometry,
                                              std::size_t self);

// The weight of projector `self` at one screen point (same as BlendField::weight;
// convenient for one-off checks, it rebuilds the field each call).
[[nodiscard]] double blend_weight(std::span<const geometry::ProjectorGeometry> group, std::size_t self,
                                  const geometry::ScreenRect& usable, double ramp, const glm::dvec2& screen);

}  // namespace optique::optics
