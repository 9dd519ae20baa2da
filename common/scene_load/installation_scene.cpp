#include "scene_load/installation_scene.h"

namespace optique::config {

Result<scene::LoadedScene> load_scene(const Installation& installation, const scene::ImageDecoder& decode,
                                      const std::string& gltf_path) {
  const SceneSource& source = installation.scene;
  return scene::load_scene(source.builtin, gltf_path.empty() ? source.gltf : gltf_path, decode,
                           installation.viewer.eye_at(0.0));
}

}  // namespace optique::config
