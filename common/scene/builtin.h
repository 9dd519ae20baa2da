#pragma once
// Procedural scenes by name, for tests and benchmarks. Each names its animated
// objects and how they move: a pure function of simulation time, so the master
// can evaluate a pose at any time and every node agrees.

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "scene/state.h"
#include "util/result.h"

namespace optique::scene {

struct AnimatedObject {
  std::uint32_t id = 0;
  std::string name;
  std::function<Pose(double seconds)> pose_at;
};

struct SceneScript {
  std::string name;
  std::vector<AnimatedObject> objects;
};

[[nodiscard]] std::span<const std::string_view> builtin_scene_names();
[[nodiscard]] bool is_builtin_scene(std::string_view name);
[[nodiscard]] Result<SceneScript> builtin_scene(std::string_view name);

}  // namespace optique::scene
