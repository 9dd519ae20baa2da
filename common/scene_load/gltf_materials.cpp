// The loader's materials: glTF's metallic-roughness factors, emissive (and its
// strength), and base colour textures through the caller's ImageDecoder.
#include "scene_load/gltf_loader.h"
#include "util/join.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace optique::scene {

float Loader::to_float(double v, const std::string& what) const {
  const auto f = static_cast<float>(v);
  if (!std::isfinite(v) || !std::isfinite(f)) fail(what + " is not a finite number");
  return f;
}

std::uint32_t Loader::material(int index, const std::string& user) {
  if (index < 0) {
    if (!default_material_) {
      materials_.push_back(Material{});  // grey, dielectric, medium rough
      default_material_ = static_cast<std::uint32_t>(materials_.size() - 1);
    }
    return *default_material_;
  }
  if (static_cast<std::size_t>(index) >= model_.materials.size()) {
    fail(user + ": material " + std::to_string(index) + " is out of range");
  }
  const auto i = static_cast<std::size_t>(index);
  if (material_index_.size() < model_.materials.size()) material_index_.resize(model_.materials.size());
  if (!material_index_[i]) {
    materials_.push_back(convert_material(i));
    material_index_[i] = static_cast<std::uint32_t>(materials_.size() - 1);
  }
  return *material_index_[i];
}

Material Loader::convert_material(std::size_t index) {
  const auto& source = model_.materials[index];
  const std::string label = labelled("material", index, source.name);
  const auto& pbr = source.pbrMetallicRoughness;
  Material out;
  if (pbr.baseColorFactor.size() < 3) fail(label + ": baseColorFactor must have 4 numbers");
  for (int c = 0; c < 3; ++c) {
    out.base_colour[c] =
        std::clamp(to_float(pbr.baseColorFactor[static_cast<std::size_t>(c)], label + ": baseColorFactor"), 0.0f, 1.0f);
  }
  out.metallic = std::clamp(to_float(pbr.metallicFactor, label + ": metallicFactor"), 0.0f, 1.0f);
  out.roughness = std::clamp(to_float(pbr.roughnessFactor, label + ": roughnessFactor"), 0.0f, 1.0f);
  float strength = 1.0f;
  const auto extension = source.extensions.find("KHR_materials_emissive_strength");
  if (extension != source.extensions.end() && extension->second.IsObject() &&
      extension->second.Has("emissiveStrength")) {
    const auto& value = extension->second.Get("emissiveStrength");
    if (!value.IsNumber()) fail(label + ": emissiveStrength is not a number");
    strength = std::max(0.0f, to_float(value.GetNumberAsDouble(), label + ": emissiveStrength"));
  }
  if (!source.emissiveFactor.empty()) {
    if (source.emissiveFactor.size() != 3) fail(label + ": emissiveFactor must have 3 numbers");
    for (int c = 0; c < 3; ++c) {
      out.emissive[c] = std::max(
          0.0f, to_float(source.emissiveFactor[static_cast<std::size_t>(c)] * strength, label + ": emissiveFactor"));
    }
  }

  if (pbr.baseColorTexture.index >= 0) out.base_colour_texture = base_colour_texture(pbr.baseColorTexture, label);
  std::vector<std::string> textures;
  if (pbr.metallicRoughnessTexture.index >= 0) textures.emplace_back("metallicRoughnessTexture");
  if (source.normalTexture.index >= 0) textures.emplace_back("normalTexture");
  if (source.occlusionTexture.index >= 0) textures.emplace_back("occlusionTexture");
  if (source.emissiveTexture.index >= 0) textures.emplace_back("emissiveTexture");
  if (!textures.empty()) {
    warn(label + ": only base colour textures are supported; ignored " + util::joined(textures));
  }
  if (!source.alphaMode.empty() && source.alphaMode != "OPAQUE") {
    warn(label + ": alphaMode " + source.alphaMode + " is ignored; drawn opaque");
  }
  return out;
}

// The texture for a material's baseColorTexture, or nothing (with a warning)
// where it cannot be had. Sampler settings are not read: the renderer always
// filters linearly (with mipmaps) and repeats.
std::optional<std::uint32_t> Loader::base_colour_texture(const tinygltf::TextureInfo& info, const std::string& label) {
  const std::string what = label + ": baseColorTexture";
  if (info.texCoord != 0) {
    warn(what + " uses TEXCOORD_" + std::to_string(info.texCoord) + " (only TEXCOORD_0 is supported); ignored");
    return std::nullopt;
  }
  if (static_cast<std::size_t>(info.index) >= model_.textures.size()) {
    fail(what + ": texture " + std::to_string(info.index) + " is out of range");
  }
  if (info.extensions.contains("KHR_texture_transform")) {
    warn(what + ": KHR_texture_transform is ignored");
  }
  const auto& texture = model_.textures[static_cast<std::size_t>(info.index)];
  if (texture.source < 0) {
    warn(what + ": texture " + std::to_string(info.index) + " has no image we can read; ignored");
    return std::nullopt;
  }
  const auto image_index = static_cast<std::size_t>(texture.source);
  if (image_index >= model_.images.size()) {
    fail(what + ": image " + std::to_string(image_index) + " is out of range");
  }
  const auto cached = texture_of_image_.find(image_index);
  if (cached != texture_of_image_.end()) return cached->second;
  auto& slot = texture_of_image_[image_index];

  const auto& image = model_.images[image_index];
  const std::string image_label = labelled("image", image_index, image.name.empty() ? image.uri : image.name);
  // Embedded (a data URI), in a buffer view, or a file beside the glTF.
  std::span<const unsigned char> encoded(image.image);
  if (image.bufferView >= 0) {
    encoded = data_.view_bytes(image.bufferView, image_label);
  } else if (image_index < source_.image_file.size() && source_.image_file[image_index]) {
    const std::string& bytes = *source_.files[*source_.image_file[image_index]].second;
    encoded = {reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size()};
  }
  if (!decode_) return std::nullopt;  // not drawn here: the image is not needed
  auto decoded = decode_(encoded, image.mimeType);
  if (!decoded) {
    warn(what + ": " + image_label + " cannot be decoded (" + decoded.error() + "); ignored");
    return std::nullopt;
  }
  Texture out = std::move(decoded.value());
  out.name = image.name.empty() ? "image " + std::to_string(image_index) : image.name;
  textures_.push_back(std::move(out));
  slot = static_cast<std::uint32_t>(textures_.size() - 1);
  return slot;
}

}  // namespace optique::scene
