#pragma once
// What a scene is made of: meshes, materials, instances of meshes (static, or
// attached to an animated object whose pose the master sends each frame), point
// lights, and the ambient term. The master needs only the animated objects; a
// node needs all of it to draw. Colours are linear light.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/state.h"

namespace optique::scene {

struct Vertex {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
};

struct Mesh {
  std::string name;
  std::vector<Vertex> vertices;
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
};

struct Material {
  glm::vec3 base_colour{0.8f};  // linear albedo
  float metallic = 0.0f;
  float roughness = 0.5f;
  glm::vec3 emissive{0.0f};  // linear radiance added as is
};

struct Instance {
  std::uint32_t mesh = 0;
  std::uint32_t material = 0;
  std::optional<std::uint32_t> object;  // animated object it rides on, if any
  glm::dmat4 transform{1.0};            // model matrix, after the object's pose if any
};

struct PointLight {
  glm::dvec3 position{0.0};
  glm::vec3 colour{1.0f};  // linear
  float intensity = 1.0f;  // radiant intensity scale: irradiance = colour·intensity / r²
};

struct AnimatedObject {
  std::uint32_t id = 0;
  std::string name;
  std::function<Pose(double seconds)> pose_at;
};

struct SceneDefinition {
  std::string name;
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Instance> instances;
  std::vector<PointLight> lights;
  glm::vec3 ambient{0.02f};  // linear irradiance-like term, times albedo
  glm::vec3 background{0.0f};
  std::vector<AnimatedObject> objects;
};

// The model matrix of a pose: translate · rotate · scale.
[[nodiscard]] glm::dmat4 model_matrix(const Pose& pose);

// A pose between two frame poses: position and scale linearly, rotation by slerp.
// `fraction` 0 is `now`, 1 is `next`; any sub-frame time lands between.
[[nodiscard]] Pose interpolate(const ObjectState& object, double fraction);

}  // namespace optique::scene
