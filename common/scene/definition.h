#pragma once
// What a scene is made of: meshes, materials, instances of meshes (static, or
// attached to an animated object whose pose the master sends each frame), point
// lights, and the ambient term. The master needs only the animated objects; a
// node needs all of it to draw. Colours are linear light, except texture texels,
// which are sRGB-encoded as image files store them (the renderer decodes them).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "scene/state.h"

namespace optique::scene {

struct Vertex {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  glm::vec2 uv{0.0f};  // texture coordinates, glTF convention: (0, 0) is the image's top-left corner
};

struct Mesh {
  std::string name;
  std::vector<Vertex> vertices;
  std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside
};

// An 8-bit RGBA image, `width`·`height`·4 bytes, top row first: colour
// sRGB-encoded, alpha linear.
struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

struct Material {
  // Not an aggregate, so that the many {colour, metallic, roughness, emissive}
  // initializations need not name the texture.
  Material() = default;
  Material(const glm::vec3& base_colour_, float metallic_, float roughness_, const glm::vec3& emissive_,
           std::optional<std::uint32_t> base_colour_texture_ = std::nullopt)
      : base_colour(base_colour_),
        metallic(metallic_),
        roughness(roughness_),
        emissive(emissive_),
        base_colour_texture(base_colour_texture_) {}

  glm::vec3 base_colour{0.8f};  // linear albedo
  float metallic = 0.0f;
  float roughness = 0.5f;
  glm::vec3 emissive{0.0f};  // linear radiance added as is
  // Multiplies base_colour (after sRGB decoding), sampled at the vertices' uv.
  std::optional<std::uint32_t> base_colour_texture;  // index into SceneDefinition::textures
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
  // What applications call it when they place it again (scene/asset_id.h):
  // set where an installation's scene is loaded; empty for a scene made in code.
  std::string asset_id;
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
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
