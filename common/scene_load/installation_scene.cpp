#include "scene_load/installation_scene.h"

#include "scene/asset_id.h"

namespace optique::config {

Result<scene::LoadedScene> load_scene(const Installation& installation, const scene::ImageDecoder& decode,
                                      const std::string& gltf_path) {
  const SceneSource& source = installation.scene;
  auto loaded = scene::load_scene(source.builtin, gltf_path.empty() ? source.gltf : gltf_path, decode,
                                  installation.viewer.eye_at(0.0), source.placement);
  // Named by the master's file, wherever this copy of it is.
  if (loaded) loaded.value().definition.asset_id = scene::scene_asset_id(source.builtin, source.gltf);
  return loaded;
}

Result<scene::LoadedScene> load_asset(const std::string& id, const std::string& path, const scene::ImageDecoder& decode,
                                      const std::string& sha256) {
  auto gltf = scene::load_gltf_scene(path, decode);
  if (!gltf) return Error{gltf.error()};
  scene::LoadedScene loaded = std::move(gltf).value();
  if (!sha256.empty() && loaded.content_sha256 != sha256) {
    return Error{path + " is not the asset '" + id + "' it was loaded as: its files have changed (sha256 " +
                 loaded.content_sha256.substr(0, 12) + "… here, " + sha256.substr(0, 12) + "… then)"};
  }
  loaded.definition.asset_id = id;
  if (!loaded.definition.lights.empty()) {
    loaded.notes.push_back(path + ": its " + std::to_string(loaded.definition.lights.size()) +
                           " light(s) are not drawn: an asset is lit by the installation's lights");
    loaded.definition.lights.clear();
  }
  return loaded;
}

}  // namespace optique::config
