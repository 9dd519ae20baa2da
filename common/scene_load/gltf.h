#pragma once
// glTF 2.0 scenes (.gltf with embedded or side files, or .glb) as a
// SceneDefinition: triangle meshes (with TEXCOORD_0; plain or compressed with
// KHR_draco_mesh_compression), metallic-roughness materials (factors, and the
// base colour texture, embedded or in a file beside the glTF), the default
// scene's node hierarchy, TRS animations and KHR_lights_punctual point lights.
// The file and what it references are read and checked first
// (scene_load/gltf_source.h: files outside the glTF's folder, missing or truncated
// files and unsupported required extensions are refused by name). Whatever the
// file uses that we cannot draw either fails the load with a message naming the
// feature (skins, morph targets, points and lines) or, where drawing without it
// is still honest, is left out with a warning: spot and directional lights;
// metallic-roughness, normal, occlusion and emissive textures; base colour
// textures on other texture coordinate sets, or whose image the decoder cannot
// read. Texture samplers are not read (the renderer filters linearly and
// repeats). A file without lights gets none here: scene/default_lights.h.
//
// Animated nodes become animated objects: every node that is the target of an
// animation channel, or has such an ancestor, and has a mesh gets its own object,
// whose pose at t is the node's world transform at t (all animations play
// together and loop over the longest one). Its instances ride on it with an
// identity transform. Static mesh nodes become instances with their world matrix.

#include <memory>
#include <string>
#include <vector>

#include "scene/definition.h"
#include "scene/image_decoder.h"
#include "scene/manifest.h"
#include "util/result.h"

namespace optique::scene {

struct LoadedGltf {
  SceneDefinition scene;
  // The files read (the glTF first), and the scene's identity: the SHA-256 of
  // their manifest (scene/manifest.h), equal on master and nodes when they
  // loaded the same content.
  SceneManifest manifest;
  std::string content_sha256;
  std::vector<std::shared_ptr<const std::string>> files;  // their bytes, as manifest.files
  // What was ignored or assumed (some textures, spot lights, a default light, ...).
  std::vector<std::string> warnings;
};

// Loads the glTF file at `path`, its base colour images read by `decode` (an
// empty decoder: none are read, the materials get no textures). Every error
// message starts with `path`.
[[nodiscard]] Result<LoadedGltf> load_gltf(const std::string& path, const ImageDecoder& decode);

}  // namespace optique::scene
