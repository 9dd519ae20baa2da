#include "geometry/homography.h"

#include <glm/geometric.hpp>

namespace optique::geometry {

glm::dvec2 apply(const glm::dmat3& h, const glm::dvec2& screen) {
  const glm::dvec3 p = h * glm::dvec3(screen, 1.0);
  return {p.x / p.z, p.y / p.z};
}

double homogeneous_w(const glm::dmat3& h, const glm::dvec2& screen) { return (h * glm::dvec3(screen, 1.0)).z; }

double reprojection_error(const glm::dmat3& h, const Correspondence& point) {
  return glm::length(apply(h, point.screen) - point.pixel);
}

}  // namespace optique::geometry
