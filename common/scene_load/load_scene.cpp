#include "scene_load/load_scene.h"

#include <fmt/format.h>

#include <filesystem>

#include "scene/builtin.h"
#include "scene/default_lights.h"
#include "scene_load/gltf.h"

namespace optique::scene {

Result<LoadedScene> load_scene(const std::string& builtin, const std::string& path, const ImageDecoder& decode,
                               const glm::dvec3& viewer) {
  LoadedScene loaded;
  if (!builtin.empty()) {
    auto definition = builtin_scene(builtin);
    if (!definition) return Error{definition.error()};
    loaded.definition = std::move(definition).value();
    loaded.source = "builtin " + builtin;
    return loaded;
  }
  auto gltf = load_gltf_scene(path, decode);
  if (!gltf) return Error{gltf.error()};
  loaded = std::move(gltf).value();
  // Either way the log says how the scene is lit (an export without lights is
  // the usual case, not a fault).
  if (loaded.definition.lights.empty()) {
    loaded.notes.push_back(path + ": " + add_default_lights(loaded.definition, viewer));
  } else {
    loaded.notes.push_back(
        fmt::format("{}: lit by the file's {} point light(s)", path, loaded.definition.lights.size()));
  }
  return loaded;
}

Result<LoadedScene> load_gltf_scene(const std::string& path, const ImageDecoder& decode) {
  auto gltf = load_gltf(path, decode);
  if (!gltf) return Error{gltf.error()};
  LoadedScene loaded;
  loaded.definition = std::move(gltf.value().scene);
  loaded.content_sha256 = gltf.value().content_sha256;
  loaded.manifest = std::move(gltf.value().manifest);
  loaded.files = std::move(gltf.value().files);
  loaded.warnings = std::move(gltf.value().warnings);
  loaded.source = path;
  return loaded;
}

}  // namespace optique::scene
