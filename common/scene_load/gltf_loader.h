#pragma once
// Internal to scene: a parsed glTF model turned into a SceneDefinition. Its
// parts, each a file: the file checked whole, its animations read and its node
// hierarchy walked (gltf_loader.cpp), meshes and Draco (gltf_meshes.cpp),
// materials and their base colour textures (gltf_materials.cpp); the binary
// data through GltfAccessors, animated poses through scene_load/gltf_animation.h.
// Throws GltfError when the file is wrong.

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "scene/definition.h"
#include "scene/image_decoder.h"
#include "scene_load/gltf_accessors.h"
#include "scene_load/gltf_animation.h"
#include "scene_load/gltf_error.h"
#include "scene_load/gltf_source.h"
#include "scene_load/tinygltf.h"

namespace optique::scene {

class Loader {
 public:
  Loader(const GltfSource& source, const tinygltf::Model& model, const ImageDecoder& decode,
         std::vector<std::string>& warnings)
      : path_(source.path),
        source_(source),
        model_(model),
        data_(model, source.path),
        decode_(decode),
        warnings_(warnings) {}

  [[nodiscard]] SceneDefinition build();

 private:
  struct Part {
    std::uint32_t mesh = 0;
    std::uint32_t material = 0;
  };
  // A primitive's vertices (positions, and normals and texture coordinates where
  // it has them) and the order they are drawn in.
  struct Attributes {
    std::vector<double> positions;
    std::vector<double> normals;
    std::vector<double> uvs;
    std::vector<std::uint32_t> order;
  };
  struct NodeTracks {
    std::optional<gltf::Sampler> translation;
    std::optional<gltf::Sampler> rotation;
    std::optional<gltf::Sampler> scale;
  };

  [[noreturn]] void fail(const std::string& what) const { throw GltfError(path_ + ": " + what); }
  void warn(const std::string& what) { warnings_.push_back(path_ + ": " + what); }
  [[nodiscard]] std::string node_label(std::size_t index) const {
    return labelled("node", index, model_.nodes[index].name);
  }

  // --- the file whole, its animations and its node hierarchy (gltf_loader.cpp)
  void check_version() const;
  void check_skins() const;
  void read_animations();
  gltf::Sampler read_sampler(const tinygltf::AnimationSampler& source, const std::string& label, bool rotation) const;
  void walk_scene();
  std::vector<double> checked(const std::vector<double>& values, std::size_t size, const std::string& what,
                              std::size_t node) const;
  // Every node's local transform; the animated ones with their tracks.
  void read_links();
  // The track of an animated node: its nearest static ancestor's world matrix and
  // the links from the topmost animated ancestor down to it.
  gltf::Track track_of(std::size_t index) const;
  std::string scene_name() const;
  void add_instances(SceneDefinition& scene);
  void add_lights(SceneDefinition& scene);

  // --- meshes (gltf_meshes.cpp)
  const std::vector<Part>& parts_of(std::size_t mesh_index, std::size_t node);
  // An attribute's values, checked to be one per vertex.
  std::vector<double> per_vertex(std::vector<double> values, std::size_t width, std::size_t vertex_count,
                                 const std::string& label, const std::string& name) const;
  // Texture coordinates: FLOAT, or normalized UNSIGNED_BYTE / UNSIGNED_SHORT.
  std::vector<double> read_uvs(int index, const std::string& label) const;
  static std::optional<int> attribute(const tinygltf::Primitive& primitive, const std::string& name);
  Attributes read_accessors(const tinygltf::Primitive& primitive, const std::string& label) const;
  // A KHR_draco_mesh_compression primitive: the attributes the extension maps
  // come from the compressed data, any other from its accessor (the extension
  // allows both); the accessors' counts must agree with what was decoded.
  Attributes read_draco(const tinygltf::Primitive& primitive, const std::string& label, std::int64_t indices,
                        int mode) const;
  std::optional<Part> convert_primitive(std::size_t mesh_index, std::size_t p);

  // --- materials (gltf_materials.cpp)
  float to_float(double v, const std::string& what) const;
  std::uint32_t material(int index, const std::string& user);
  Material convert_material(std::size_t index);
  // The texture for a material's baseColorTexture, or nothing (with a warning)
  // where it cannot be had. Sampler settings are not read: the renderer always
  // filters linearly (with mipmaps) and repeats.
  std::optional<std::uint32_t> base_colour_texture(const tinygltf::TextureInfo& info, const std::string& label);

  std::string path_;
  const GltfSource& source_;
  const tinygltf::Model& model_;
  GltfAccessors data_;
  const ImageDecoder& decode_;
  std::vector<std::string>& warnings_;

  std::map<std::size_t, NodeTracks> channels_;  // by node
  double duration_ = 0.0;
  int scene_index_ = -1;
  std::vector<int> parent_;
  std::vector<std::size_t> order_;  // the scene's nodes, parents first
  std::vector<bool> animated_;
  std::vector<gltf::Link> links_;
  std::vector<glm::dmat4> world0_;  // world transforms at t = 0

  std::vector<Mesh> meshes_;
  std::vector<Material> materials_;
  std::vector<Texture> textures_;
  std::map<std::size_t, std::optional<std::uint32_t>> texture_of_image_;  // decoded (or not) glTF images
  std::vector<std::optional<std::vector<Part>>> parts_;                   // by glTF mesh
  std::vector<std::optional<std::uint32_t>> material_index_;
  std::optional<std::uint32_t> default_material_;
};

}  // namespace optique::scene
