#include "scene_load/load_scene.h"

#include <fmt/format.h>

#include <filesystem>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "scene/builtin.h"
#include "scene/default_lights.h"
#include "scene_load/gltf.h"

namespace optique::scene {

namespace {

std::string metres(const glm::dvec3& v) { return fmt::format("({:.3g}, {:.3g}, {:.3g})", v.x, v.y, v.z); }

// A viewer closer than this to the model's bounds stands in it or at it.
constexpr double kBeside = 0.1;  // metres

// Where the model stands, placed, and what the log and check-config say of it.
void place_model(LoadedScene& loaded, const std::string& path, const glm::dvec3& viewer,
                 const std::optional<Placement>& placement) {
  SceneDefinition& scene = loaded.definition;
  std::string how = "as the file has it";
  if (placement) {
    const Pose pose = place(scene, *placement);
    how = fmt::format("placed{}: scaled {:.4g}", placement->fit ? " to fit" : "", pose.scale.x);
  }
  const std::optional<Box> bounds = world_bounds(scene);
  if (!bounds) {
    loaded.notes.push_back(path + ": nothing to draw");
    return;
  }
  const glm::dvec3 size = bounds->size();
  loaded.notes.push_back(fmt::format("{}: {:.3g} × {:.3g} × {:.3g} m (width, height, depth), from {} to {} m, {}", path,
                                     size.x, size.y, size.z, metres(bounds->low), metres(bounds->high), how));
  const glm::dvec3 nearest = glm::clamp(viewer, bounds->low, bounds->high);
  if (glm::length(viewer - nearest) < kBeside) {
    // A note, not a warning: a room or a building around the viewer is what a CAVE is for.
    loaded.notes.push_back(fmt::format(
        "{}: the viewer's eye {} is {} the model ({} to {} m): right for a room around the viewer; a model to "
        "be seen from outside is drawn around them, mostly behind the screens: place it (scene.placement)",
        path, metres(viewer), nearest == viewer ? "inside" : "beside", metres(bounds->low), metres(bounds->high)));
  }
}

}  // namespace

Result<LoadedScene> load_scene(const std::string& builtin, const std::string& path, const ImageDecoder& decode,
                               const glm::dvec3& viewer, const std::optional<Placement>& placement) {
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
  place_model(loaded, path, viewer, placement);
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
