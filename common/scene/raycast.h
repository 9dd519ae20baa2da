#pragma once
// Rays against a scene as the renderer draws it, on the CPU: what the master
// needs to estimate which surfaces a node shows (the automatic light split)
// without a GPU. Brute force over every triangle, in double; instances whose
// world bounding box the ray misses are skipped.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/definition.h"
#include "scene/state.h"

namespace optique::scene {

struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  // non-zero, need not be unit
};

struct Hit {
  double t = 0.0;              // the point is origin + t·direction
  glm::dvec3 point{0.0};       // world space
  glm::dvec3 normal{0.0};      // the triangle's geometric normal, unit, facing the ray's origin
  std::uint32_t instance = 0;  // index into SceneDefinition::instances
};

// The nearest surface the ray meets (t > 0), drawn as the renderer draws it: both
// faces of every triangle, animated instances at `fraction` between the frame's
// two poses, instances whose object is missing from `state` left out. Nothing when
// it meets nothing. Degenerate triangles (zero area) are never hit.
[[nodiscard]] std::optional<Hit> cast_ray(const SceneDefinition& scene, const SceneState& state, double fraction,
                                          const Ray& ray);

// The same for many rays against one frame: places every instance once (world
// space vertices and bounding boxes) instead of once per ray. Keeps references
// to `scene`'s meshes, so `scene` must outlive it; `state` is not kept.
class RayCaster {
 public:
  RayCaster(const SceneDefinition& scene, const SceneState& state, double fraction);

  [[nodiscard]] std::optional<Hit> cast(const Ray& ray) const;

 private:
  struct Box {
    glm::dvec3 lo{0.0};
    glm::dvec3 hi{0.0};
  };
  // A run of consecutive triangles with its box: meshes list neighbouring
  // triangles together, so a ray skips most of a large mesh run by run.
  struct Chunk {
    Box box;
    std::size_t first_index = 0;  // into the mesh's indices
    std::size_t end_index = 0;
  };
  struct Placed {
    std::uint32_t instance = 0;
    const std::vector<std::uint32_t>* indices = nullptr;  // the mesh's
    std::vector<glm::dvec3> vertices;                     // world space
    Box box;
    std::vector<Chunk> chunks;
  };

  std::vector<Placed> placed_;
};

}  // namespace optique::scene
