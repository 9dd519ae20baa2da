#pragma once
// A config drawn in-process, as gpu tests do: its installation, its scene loaded
// as the master loads it, and a headless GL context current on this thread.

#include <memory>
#include <string>

#include "config/load.h"
#include "render/gl_context.h"
#include "scene/definition.h"
#include "util/result.h"

namespace optique::testing {

struct GlInstallation {
  std::unique_ptr<render::GlContext> context;
  config::LoadedConfig config;
  scene::SceneDefinition scene;
};

[[nodiscard]] Result<GlInstallation> open_gl_installation(const std::string& config_path);

}  // namespace optique::testing
