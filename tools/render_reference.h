#pragma once
// `optique-master render-reference`: what a viewer should see on each screen at
// one frame, drawn in this process: the eye's view of each whole screen rectangle
// at the screen's pixels per metre, with the same renderer the nodes use. Tests
// compare node captures and screen composites against these.

#include <cstdint>
#include <string>

#include <spdlog/logger.h>

#include "config/load.h"
#include "master/session/journal.h"
#include "scene_load/load_scene.h"
#include "util/result.h"

namespace optique::tools {

struct ReferenceOptions {
  // Renders at supersample × the screen's pixels and averages each block down
  // (box filter, linear light; the PNG is encoded from the averaged image), so
  // that each pixel holds the light over its footprint as screen composites do.
  // 1 = one sample per pixel centre.
  int supersample = 1;
  // A recorded session (the master's --record): the frame shows the live
  // instances its last run, played again, puts in it (the master's --replay).
  const master::Journal* replay = nullptr;
};

// Writes OUT/reference/<screen-id>/frame-NNNNNN.exr and .png for every screen.
[[nodiscard]] Result<void> render_reference(const config::LoadedConfig& config, const scene::LoadedScene& scene,
                                            std::uint64_t frame, const std::string& out_dir, spdlog::logger& log,
                                            const ReferenceOptions& options = {});

}  // namespace optique::tools
