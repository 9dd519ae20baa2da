#pragma once
// The scene an installation names, built in or from a glTF file, loaded the same
// way by the master (to animate it) and by every node (to draw it).

#include <string>
#include <vector>

#include "scene/definition.h"
#include "scene/image_decoder.h"
#include "util/result.h"

namespace optique::scene {

struct LoadedScene {
  SceneDefinition definition;
  std::string source;          // "builtin cubes" or the glTF file's path
  std::string content_sha256;  // of the glTF content; empty for built-in scenes
  std::vector<std::string> warnings;
};

// A glTF path relative to `config_dir` becomes absolute, so nodes started
// elsewhere load the same file.
[[nodiscard]] std::string resolve_asset(const std::string& path, const std::string& config_dir);

// The built-in scene `builtin`, or else the glTF file at `gltf` (absolute, or
// relative to the working folder); `decode` reads its images (empty: none are
// read; see scene/image_decoder.h).
[[nodiscard]] Result<LoadedScene> load_scene(const std::string& builtin, const std::string& gltf,
                                             const ImageDecoder& decode);

}  // namespace optique::scene
