#include "scene/raycast.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>
#include "util/finite.h"

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

namespace optique::scene {
namespace {

// Triangles per chunk: small enough that a ray skips most of a large mesh, large
// enough that the boxes cost little next to the triangles.
constexpr std::size_t kChunkTriangles = 64;

using util::finite;

// Whether the ray meets `lo`..`hi` somewhere in (0, t_max]. The slab test, with
// axis-parallel rays handled apart so that 0·∞ never makes a NaN.
bool meets(const glm::dvec3& lo, const glm::dvec3& hi, const Ray& ray, double t_max) {
  double near = 0.0;
  double far = t_max;
  for (int a = 0; a < 3; ++a) {
    if (ray.direction[a] == 0.0) {
      if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return false;
      continue;
    }
    const double inverse = 1.0 / ray.direction[a];
    double t0 = (lo[a] - ray.origin[a]) * inverse;
    double t1 = (hi[a] - ray.origin[a]) * inverse;
    if (t0 > t1) std::swap(t0, t1);
    near = std::max(near, t0);
    far = std::min(far, t1);
    if (near > far) return false;
  }
  return true;
}

struct TriangleHit {
  double t = 0.0;
  glm::dvec3 normal{0.0};  // unit, facing the ray's origin
};

// Möller–Trumbore, both faces. Degenerate triangles (no area, or NaN corners) and
// rays in the triangle's plane never hit: those are the cases whose division
// would make the NaN or the huge t that must not come out.
std::optional<TriangleHit> intersect(const Ray& ray, const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2) {
  const glm::dvec3 e1 = v1 - v0;
  const glm::dvec3 e2 = v2 - v0;
  const glm::dvec3 n = glm::cross(e1, e2);
  const double n2 = glm::dot(n, n);
  // Relative to the edges, so that the test does not depend on the scene's units;
  // written so that NaN fails it.
  if (!(n2 > 1e-24 * glm::dot(e1, e1) * glm::dot(e2, e2))) return std::nullopt;
  const glm::dvec3 p = glm::cross(ray.direction, e2);
  const double det = glm::dot(e1, p);  // = −direction·n
  if (!(det * det > 1e-24 * n2 * glm::dot(ray.direction, ray.direction))) return std::nullopt;
  const double inverse = 1.0 / det;
  const glm::dvec3 s = ray.origin - v0;
  const double u = glm::dot(s, p) * inverse;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(ray.direction, q) * inverse;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = glm::dot(e2, q) * inverse;
  if (!(t > 0.0) || !std::isfinite(t)) return std::nullopt;
  glm::dvec3 normal = n / std::sqrt(n2);
  if (glm::dot(normal, ray.direction) > 0.0) normal = -normal;
  return TriangleHit{t, normal};
}

}  // namespace

RayCaster::RayCaster(const SceneDefinition& scene, const SceneState& state, double fraction) {
  assert(std::isfinite(fraction));
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    assert(instance.mesh < scene.meshes.size());
    glm::dmat4 model = instance.transform;
    if (instance.object) {
      const auto found = state.objects.find(*instance.object);
      if (found == state.objects.end()) continue;  // the renderer does not draw it either
      model = model_matrix(interpolate(found->second, fraction)) * instance.transform;
    }
    const Mesh& mesh = scene.meshes[instance.mesh];
    Placed placed;
    placed.instance = static_cast<std::uint32_t>(i);
    placed.indices = &mesh.indices;
    placed.vertices.reserve(mesh.vertices.size());
    bool all_finite = true;
    for (const Vertex& vertex : mesh.vertices) {
      const glm::dvec3 world(model * glm::dvec4(glm::dvec3(vertex.position), 1.0));
      all_finite = all_finite && finite(world);
      placed.vertices.push_back(world);
    }
    // States are checked for finite numbers on the way in; should one slip
    // through, its instance is left out rather than turned into NaN hits.
    if (!all_finite) continue;

    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    placed.box = {glm::dvec3(kInfinity), glm::dvec3(-kInfinity)};
    const std::size_t triangle_indices = mesh.indices.size() / 3 * 3;
    for (std::size_t first = 0; first < triangle_indices; first += 3 * kChunkTriangles) {
      Chunk chunk{{glm::dvec3(kInfinity), glm::dvec3(-kInfinity)},
                  first,
                  std::min(first + 3 * kChunkTriangles, triangle_indices)};
      for (std::size_t k = chunk.first_index; k < chunk.end_index; ++k) {
        assert(mesh.indices[k] < placed.vertices.size());
        const glm::dvec3& p = placed.vertices[mesh.indices[k]];
        chunk.box.lo = glm::min(chunk.box.lo, p);
        chunk.box.hi = glm::max(chunk.box.hi, p);
      }
      // A little slack: the slab test and the triangle test round differently,
      // and a flat box (a quad) must not lose the ray that grazes it.
      const glm::dvec3 slack = 1e-9 * (glm::abs(chunk.box.lo) + glm::abs(chunk.box.hi)) + 1e-12;
      chunk.box.lo -= slack;
      chunk.box.hi += slack;
      placed.box.lo = glm::min(placed.box.lo, chunk.box.lo);
      placed.box.hi = glm::max(placed.box.hi, chunk.box.hi);
      placed.chunks.push_back(chunk);
    }
    if (placed.chunks.empty()) continue;  // no triangles
    placed_.push_back(std::move(placed));
  }
}

std::optional<Hit> RayCaster::cast(const Ray& ray) const {
  assert(finite(ray.origin) && finite(ray.direction));
  assert(ray.direction != glm::dvec3(0.0));
  std::optional<Hit> best;
  double best_t = std::numeric_limits<double>::infinity();
  for (const Placed& placed : placed_) {
    if (!meets(placed.box.lo, placed.box.hi, ray, best_t)) continue;
    const std::vector<std::uint32_t>& indices = *placed.indices;
    for (const Chunk& chunk : placed.chunks) {
      if (!meets(chunk.box.lo, chunk.box.hi, ray, best_t)) continue;
      for (std::size_t k = chunk.first_index; k < chunk.end_index; k += 3) {
        const auto hit = intersect(ray, placed.vertices[indices[k]], placed.vertices[indices[k + 1]],
                                   placed.vertices[indices[k + 2]]);
        // Strictly nearer: on a tie the first instance and triangle keep it.
        if (!hit || !(hit->t < best_t)) continue;
        best_t = hit->t;
        best = Hit{hit->t, ray.origin + hit->t * ray.direction, hit->normal, placed.instance};
      }
    }
  }
  return best;
}

std::optional<Hit> cast_ray(const SceneDefinition& scene, const SceneState& state, double fraction, const Ray& ray) {
  return RayCaster(scene, state, fraction).cast(ray);
}

}  // namespace optique::scene
