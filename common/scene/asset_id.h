#pragma once
// The id by which an application names the installation's own scene when it
// places it again (master.api): the built-in scene's name, or the glTF file's
// name without its folder and extension. The master and every node derive it
// the same way from the config's scene.

#include <string>

namespace optique::scene {

// Characters an id may not hold (util/id_text.h) become '-'; at most
// kMaxInstanceIdLength of them; "scene" when nothing is left.
[[nodiscard]] std::string scene_asset_id(const std::string& builtin, const std::string& gltf_path);

}  // namespace optique::scene
