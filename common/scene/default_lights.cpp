#include "scene/default_lights.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <glm/geometric.hpp>

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

struct Bounds {
  glm::dvec3 low{std::numeric_limits<double>::infinity()};
  glm::dvec3 high{-std::numeric_limits<double>::infinity()};
};

// The world bounds of everything drawn, as it stands at t = 0.
Bounds bounds_of(const SceneDefinition& scene) {
  Bounds bounds;
  for (const Instance& instance : scene.instances) {
    glm::dmat4 transform = instance.transform;
    if (instance.object) {
      for (const AnimatedObject& object : scene.objects) {
        if (object.id == *instance.object) transform = model_matrix(object.pose_at(0.0)) * transform;
      }
    }
    for (const Vertex& vertex : scene.meshes[instance.mesh].vertices) {
      const glm::dvec3 p(transform * glm::dvec4(glm::dvec3(vertex.position), 1.0));
      bounds.low = glm::min(bounds.low, p);
      bounds.high = glm::max(bounds.high, p);
    }
  }
  return bounds;
}

PointLight light(const glm::dvec3& centre, const glm::dvec3& direction, double distance, double irradiance) {
  PointLight out;
  out.position = centre + distance * glm::normalize(direction);
  out.intensity = static_cast<float>(irradiance * std::numbers::pi * distance * distance);
  return out;
}

}  // namespace

std::string add_default_lights(SceneDefinition& scene, const glm::dvec3& viewer) {
  const Bounds bounds = bounds_of(scene);
  glm::dvec3 centre(0.0);
  double radius = 1.0;
  if (util::finite(bounds.low) && util::finite(bounds.high)) {
    centre = 0.5 * (bounds.low + bounds.high);
    radius = std::max(0.5 * glm::length(bounds.high - bounds.low), 1e-3);
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
