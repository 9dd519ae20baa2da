#include "scene/light_coverage.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "scene/raycast.h"

namespace optique::scene {

std::vector<std::optional<PointLight>> frame_lights(const SceneDefinition& scene, const SceneState& state) {
  std::size_t count = scene.lights.size();
  if (!state.point_lights.empty()) count = std::max(count, std::size_t{state.point_lights.rbegin()->first} + 1);
  std::vector<std::optional<PointLight>> lights(count);
  std::copy(scene.lights.begin(), scene.lights.end(), lights.begin());
  for (const auto& [index, added] : state.point_lights) {
    // The master adds none over the scene's own; a peer's that would is not drawn.
    if (index < scene.lights.size()) continue;
    lights[index] = PointLight{added.position, glm::vec3(added.colour), static_cast<float>(added.intensity)};
  }
  return lights;
}

std::vector<double> light_coverage(const SceneDefinition& scene, const SceneState& state, const CoverageGrid& grid) {
  assert(grid.nx > 0 && grid.ny > 0);
  assert(std::isfinite(grid.threshold) && grid.threshold >= 0.0);
  const std::vector<std::optional<PointLight>> lights = frame_lights(scene, state);
  std::vector<std::size_t> reached(lights.size(), 0);
  // Frame 0 of the pair: the split is chosen for a frame, not for a sub-frame time.
  const RayCaster caster(scene, state, 0.0);
  for (int j = 0; j < grid.ny; ++j) {
    const double t = (j + 0.5) / grid.ny;
    for (int i = 0; i < grid.nx; ++i) {
      const double s = (i + 0.5) / grid.nx;
      const glm::dvec3 target = grid.corner + s * grid.across + t * grid.up;
      const glm::dvec3 direction = target - grid.eye;
      // The eye on the screen itself sees nothing through this cell.
      if (direction == glm::dvec3(0.0)) continue;
      const auto hit = caster.cast({grid.eye, direction});
      if (!hit) continue;
      for (std::size_t k = 0; k < lights.size(); ++k) {
        if (!lights[k]) continue;
        const PointLight& light = *lights[k];
        const glm::dvec3 to_light = light.position - hit->point;
        // The same floor on r² as the shader, so a light on the surface is not infinite.
        const double r2 = std::max(glm::dot(to_light, to_light), 1e-8);
        const double n_dot_l = glm::dot(hit->normal, to_light) / std::sqrt(r2);
        if (!(n_dot_l > 0.0)) continue;
        const double strength = static_cast<double>(light.intensity) *
                                static_cast<double>(glm::max(light.colour.r, glm::max(light.colour.g, light.colour.b)));
        if (strength * n_dot_l / r2 >= grid.threshold) ++reached[k];
      }
    }
  }
  const double samples = static_cast<double>(grid.nx) * static_cast<double>(grid.ny);
  std::vector<double> coverage(reached.size());
  std::transform(reached.begin(), reached.end(), coverage.begin(),
                 [samples](std::size_t count) { return static_cast<double>(count) / samples; });
  return coverage;
}

}  // namespace optique::scene
