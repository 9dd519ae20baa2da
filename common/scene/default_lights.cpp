#include "scene/default_lights.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "scene/placement.h"
#include "util/finite.h"

namespace optique::scene {

namespace {

// Irradiance each light gives a surface facing it at the scene's centre, in
// units of π: the renderer's diffuse term is albedo/π · irradiance · cos, so 1
// shows the albedo itself. The key does most of it; the fill keeps the other
// side from going black; the rim outlines the model against the background.
constexpr double kKey = 0.85;
constexpr double kFill = 0.35;
constexpr double kRim = 0.4;
// The ambient term (times the albedo): what the lights do not reach stays visible.
constexpr float kAmbient = 0.08f;
// The lights stand this many times the scene's radius from its centre: far
// enough that light falls off little across it (a factor 1.5² between its near
// and far side), near enough to model its shape.
constexpr double kDistance = 5.0;

PointLight light(const glm::dvec3& centre, const glm::dvec3& direction, double distance, double irradiance) {
  PointLight out;
  out.position = centre + distance * glm::normalize(direction);
  out.intensity = static_cast<float>(irradiance * std::numbers::pi * distance * distance);
  return out;
}

}  // namespace

std::string add_default_lights(SceneDefinition& scene, const glm::dvec3& viewer) {
  const std::optional<Box> bounds = world_bounds(scene);
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (bounds && util::finite(bounds->low) && util::finite(bounds->high)) {
    centre = bounds->centre();
    radius = std::max(0.5 * glm::length(bounds->size()), 1e-3);
  }
  // The viewer's frame: forward to the scene, right, and up as near the world's
  // +y (glTF's up) as forward allows.
  glm::dvec3 forward = util::finite(viewer) ? centre - viewer : glm::dvec3(0.0, 0.0, -1.0);
  forward = glm::length(forward) > 1e-9 ? glm::normalize(forward) : glm::dvec3(0.0, 0.0, -1.0);
  const glm::dvec3 world_up = std::abs(forward.y) < 0.95 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(0.0, 0.0, -1.0);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, world_up));
  const glm::dvec3 up = glm::cross(right, forward);

  const double distance = kDistance * radius;
  // Key: from the viewer's side, above and to the left; fill: level, from the
  // right; rim: from behind, above.
  scene.lights.push_back(light(centre, -forward + 0.7 * up - 0.6 * right, distance, kKey));
  scene.lights.push_back(light(centre, -forward + 0.9 * right, distance, kFill));
  scene.lights.push_back(light(centre, forward + 0.9 * up + 0.3 * right, distance, kRim));
  scene.ambient = glm::max(scene.ambient, glm::vec3(kAmbient));
  return fmt::format(
      "no point lights to draw in the file: lit by a key, a fill and a rim light {:.2f} m from the centre of the scene "
      "({:.2f}, {:.2f}, {:.2f}; radius {:.2f} m) as seen from the viewer at ({:.2f}, {:.2f}, {:.2f})",
      distance, centre.x, centre.y, centre.z, radius, viewer.x, viewer.y, viewer.z);
}

}  // namespace optique::scene
