#include "geometry/oblique_depth.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "geometry/projector_geometry.h"

namespace optique::geometry {

Result<ObliqueDepth> oblique_depth(const glm::dmat3& h, ImageSize image) {
  auto geometry = geometry::ProjectorGeometry::make(h, image.width, image.height);
  if (!geometry) return Error{geometry.error()};
  // The whole plane is usable here: R is the bounding rectangle of the lit quad.
  constexpr double kEverywhere = std::numeric_limits<double>::infinity();
  auto projection = geometry::oblique_projection(geometry.value(), {glm::dvec2(-kEverywhere), glm::dvec2(kEverywhere)});
  if (!projection) return Error{projection.error()};
  glm::dmat3 a = projection.value().user_to_projector;
  double norm = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) norm += a[c][r] * a[c][r];
  }
  norm = std::sqrt(norm);
  if (!(std::abs(a[2][2]) > 1e-12 * norm)) {
    return Error{
        fmt::format("a33 ≈ 0 ({:.3g} of ‖A‖): the centre of the lit area's bounding rectangle is on the "
                    "projector's horizon",
                    a[2][2] / norm)};
  }
  a /= a[2][2];
  ObliqueDepth d;
  d.rect_min = projection.value().bounds.min;
  d.rect_max = projection.value().bounds.max;
  d.a = a;
  d.factor = std::abs(a[0][2]) + std::abs(a[1][2]);
  d.depth_scale = projection.value().depth_scale;
  return d;
}

}  // namespace optique::geometry
