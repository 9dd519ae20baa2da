#include "scene/asset_id.h"

#include <algorithm>

#include "scene/state.h"
#include "util/id_text.h"

namespace optique::scene {

std::string scene_asset_id(const std::string& builtin, const std::string& gltf_path) {
  std::string id = builtin;
  if (id.empty()) {
    const std::size_t slash = gltf_path.find_last_of('/');
    id = gltf_path.substr(slash == std::string::npos ? 0 : slash + 1);
    if (const std::size_t dot = id.rfind('.'); dot != std::string::npos && dot > 0) id.resize(dot);
  }
  if (id.size() > kMaxInstanceIdLength) id.resize(kMaxInstanceIdLength);
  std::replace_if(
      id.begin(), id.end(), [](char c) { return !util::is_id_char(c); }, '-');
  return id.empty() ? "scene" : id;
}

}  // namespace optique::scene
