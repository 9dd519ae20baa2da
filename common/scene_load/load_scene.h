#pragma once
// The scene an installation names, built in or from a glTF file, loaded the same
// way by the master (to animate it and to send its files to nodes that lack
// them) and by every node (to draw it). The installation's own entry point is
// config::load_scene (scene_load/installation_scene.h).

#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/definition.h"
#include "scene/image_decoder.h"
#include "scene/manifest.h"
#include "scene/placement.h"
#include "util/result.h"

namespace optique::scene {

struct LoadedScene {
  SceneDefinition definition;
  std::string source;          // "builtin cubes" or the glTF file's path
  std::string content_sha256;  // the glTF's identity (its manifest's SHA-256); empty for built-in scenes
  SceneManifest manifest;      // the glTF's files; none for built-in scenes
  std::vector<std::shared_ptr<const std::string>> files;  // their bytes, as manifest.files
  std::vector<std::string> warnings;                      // what the file asked for that is left out or changed
  std::vector<std::string> notes;                         // what was done that is no fault: how a glTF is lit
};

// The built-in scene `builtin`, or else the glTF file at `gltf` (absolute, or
// relative to the working folder) placed by `placement` (scene/placement.h;
// none: where the file has it); `decode` reads its images (empty: none are
// read; see scene/image_decoder.h). A glTF without lights is lit by
// scene/default_lights.h for a viewer at `viewer`. Its notes say how large it
// is and where it stands, and whether the viewer stands in it.
[[nodiscard]] Result<LoadedScene> load_scene(const std::string& builtin, const std::string& gltf,
                                             const ImageDecoder& decode, const glm::dvec3& viewer,
                                             const std::optional<Placement>& placement = std::nullopt);

// The glTF file at `path` as it is (no lights added).
[[nodiscard]] Result<LoadedScene> load_gltf_scene(const std::string& path, const ImageDecoder& decode);

}  // namespace optique::scene
