#pragma once
// Everything a run needs before anything starts: the installation, the scene it
// names, the checks that relate the two (lighting groups, light switches) and the
// shared secret, a tracking replay's samples. The master and the tools load a
// config the same way.

#include <string>
#include <utility>

#include "config/load.h"
#include "scene/image_decoder.h"
#include "scene_load/load_scene.h"
#include "tracking/replay.h"
#include "util/result.h"

namespace optique::master {

struct RunConfig {
  config::LoadedConfig config;
  scene::LoadedScene scene;
  std::vector<tracking::ReplaySample> replay;  // viewer.tracking with source replay
};

// `decode` reads the scene's images: the master, which never draws, passes none;
// the tools that draw or check them pass image::decode_texture.
[[nodiscard]] Result<RunConfig> load_run_config(const std::string& path, const scene::ImageDecoder& decode);

}  // namespace optique::master
