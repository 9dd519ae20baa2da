#pragma once
// glTF 2.0 scenes (.gltf with embedded or side buffers, or .glb) as a
// SceneDefinition: triangle meshes (with TEXCOORD_0), metallic-roughness
// materials (factors, and the base colour texture), the default scene's node
// hierarchy, TRS animations and KHR_lights_punctual point lights. Whatever the
// file uses that we cannot draw either fails the load with a message naming the
// feature (skins, morph targets, unknown required extensions, points and lines)
// or, where drawing without it is still honest, is left out with a warning: spot
// and directional lights; metallic-roughness, normal, occlusion and emissive
// textures; base colour textures on other texture coordinate sets, in external
// image files, or whose image the decoder cannot read. Texture samplers are
// not read (the renderer filters linearly and repeats).
//
// Animated nodes become animated objects: every node that is the target of an
// animation channel, or has such an ancestor, and has a mesh gets its own object,
// whose pose at t is the node's world transform at t (all animations play
// together and loop over the longest one). Its instances ride on it with an
// identity transform. Static mesh nodes become instances with their world matrix.

#include <string>
#include <vector>

#include "scene/definition.h"
#include "scene/image_decoder.h"
#include "util/result.h"

namespace optique::scene {

struct LoadedGltf {
  SceneDefinition scene;
  // SHA-256 (hex) of the .gltf/.glb file's bytes followed by those of every
  // external buffer file, in buffer order: equal on master and nodes when they
  // loaded the same content.
  std::string content_sha256;
  // What was ignored or assumed (some textures, spot lights, a default light, ...).
  std::vector<std::string> warnings;
};

// Loads the glTF file at `path`, its base colour images read by `decode` (an
// empty decoder: none are read, the materials get no textures). Every error
// message starts with `path`.
[[nodiscard]] Result<LoadedGltf> load_gltf(const std::string& path, const ImageDecoder& decode);

}  // namespace optique::scene
