#include "scene/placement.h"

#include <algorithm>
#include <cassert>
#include <limits>

#include <glm/gtc/quaternion.hpp>

namespace optique::scene {

std::optional<Box> world_bounds(const SceneDefinition& scene) {
  glm::dvec3 low{std::numeric_limits<double>::infinity()};
  glm::dvec3 high{-std::numeric_limits<double>::infinity()};
  bool any = false;
  for (const Instance& instance : scene.instances) {
    glm::dmat4 transform = instance.transform;
    if (instance.object) {
      for (const AnimatedObject& object : scene.objects) {
        if (object.id == *instance.object) transform = model_matrix(object.pose_at(0.0)) * transform;
      }
    }
    for (const Vertex& vertex : scene.meshes[instance.mesh].vertices) {
      const glm::dvec3 p(transform * glm::dvec4(glm::dvec3(vertex.position), 1.0));
      low = glm::min(low, p);
      high = glm::max(high, p);
      any = true;
    }
  }
  if (!any) return std::nullopt;
  return Box{low, high};
}

namespace {

// `outer` after `inner`, both with a scale alike on every axis (then the two
// make one pose: the uniform scale commutes with the rotation).
Pose after(const Pose& outer, const Pose& inner) {
  Pose pose;
  pose.position = outer.position + outer.scale.x * (outer.rotation * inner.position);
  pose.rotation = outer.rotation * inner.rotation;
  pose.scale = outer.scale.x * inner.scale;
  return pose;
}

}  // namespace

void move(SceneDefinition& scene, const Pose& pose) {
  assert(pose.scale.x == pose.scale.y && pose.scale.y == pose.scale.z);
  const glm::dmat4 matrix = model_matrix(pose);
  for (Instance& instance : scene.instances) {
    // One riding an animated object moves with the object's pose, below.
    if (!instance.object) instance.transform = matrix * instance.transform;
  }
  for (AnimatedObject& object : scene.objects) {
    object.pose_at = [pose, inner = std::move(object.pose_at)](double seconds) { return after(pose, inner(seconds)); };
  }
  for (PointLight& light : scene.lights) {
    light.position = glm::dvec3(matrix * glm::dvec4(light.position, 1.0));
    // As far from what it lights as before, relative to the model's size.
    light.intensity *= static_cast<float>(pose.scale.x * pose.scale.x);
  }
}

Pose place(SceneDefinition& scene, const Placement& placement) {
  Pose turned;
  turned.rotation = placement.rotation;
  if (!placement.fit) {
    turned.position = placement.position;
    turned.scale = glm::dvec3(placement.scale);
    move(scene, turned);
    return turned;
  }
  move(scene, turned);
  const std::optional<Box> bounds = world_bounds(scene);
  if (!bounds) return turned;
  const glm::dvec3 size = bounds->size();
  const glm::dvec3 room = placement.fit->size;
  // The tightest axis decides; a flat model (no extent along an axis) is
  // scaled by the others; one with no extent at all keeps its size.
  double scale = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (size[axis] > 0.0) scale = std::min(scale, room[axis] / size[axis]);
  }
  if (!(scale < std::numeric_limits<double>::infinity())) scale = 1.0;
  Pose fitted;
  fitted.scale = glm::dvec3(scale);
  fitted.position = placement.fit->centre - scale * bounds->centre();
  move(scene, fitted);
  return after(fitted, turned);
}

}  // namespace optique::scene
