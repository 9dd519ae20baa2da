#pragma once
// `optique-master render-reference`: what a viewer should see on each screen at
// one frame, drawn in this process: the eye's view of each whole screen rectangle
// at the screen's pixels per metre, with the same renderer the nodes use. Tests
// compare node captures and screen composites against these.

#include <cstdint>
#include <string>

#include <spdlog/logger.h>

#include "config/load.h"
#include "scene/load_scene.h"
#include "util/result.h"

namespace optique::master {

// Writes OUT/reference/<screen-id>/frame-NNNNNN.exr and .png for every screen.
[[nodiscard]] Result<void> render_reference(const config::LoadedConfig& config, const scene::LoadedScene& scene,
                                            std::uint64_t frame, const std::string& out_dir, spdlog::logger& log);

}  // namespace optique::master
