#pragma once
// An installation's scene, loaded the one way the master, the nodes, the tools
// and the tests load it.

#include <string>

#include "config/installation.h"
#include "scene/image_decoder.h"
#include "scene_load/load_scene.h"
#include "util/result.h"

namespace optique::config {

// The scene `installation` names: built in, or its glTF file — read from
// `gltf_path` instead when given (a node's copy of the master's files) — lit
// from where the viewer's eyes rest (at t = 0) when the file brings no lights.
[[nodiscard]] Result<scene::LoadedScene> load_scene(const Installation& installation, const scene::ImageDecoder& decode,
                                                    const std::string& gltf_path = {});

// An asset an application loaded (the scene session's LoadAsset), named
// `id`: the glTF file at `path`, loaded as a scene's is. It is drawn lit by
// the installation's lights: its own lights (none are added) are dropped and
// said so in its notes. With `sha256` (its identity when it was loaded: a
// journal's, a master's offer), files that hash otherwise are refused.
[[nodiscard]] Result<scene::LoadedScene> load_asset(const std::string& id, const std::string& path,
                                                    const scene::ImageDecoder& decode, const std::string& sha256 = {});

}  // namespace optique::config
