#pragma once
// Procedural scenes by name, for tests and benchmarks: their content (meshes,
// materials, lights) and their animated objects, whose motion is a pure function
// of simulation time so the master can evaluate a pose at any time and every
// node agrees.

#include <span>
#include <string_view>

#include "scene/definition.h"
#include "util/result.h"

namespace optique::scene {

[[nodiscard]] std::span<const std::string_view> builtin_scene_names();
[[nodiscard]] bool is_builtin_scene(std::string_view name);
[[nodiscard]] Result<SceneDefinition> builtin_scene(std::string_view name);

}  // namespace optique::scene
