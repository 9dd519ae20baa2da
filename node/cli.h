#pragma once

#include <functional>
#include <memory>
#include <string>

#include <spdlog/logger.h>

#include "node/renderer.h"

namespace optique::node {

// Makes the GL renderer, which writes captures to `capture_dir`.
using GlRendererFactory = std::function<std::unique_ptr<Renderer>(spdlog::logger& log, const std::string& capture_dir)>;

// The whole node command line; returns the process exit status. optique-node
// links no GL and passes no factory: a node that is to draw with GL becomes
// optique-node-gl (the same arguments, the same process), so a null-renderer
// node loads no GL or image library. optique-node-gl passes its factory.
[[nodiscard]] int run_cli(int argc, char** argv, const GlRendererFactory& make_gl);

}  // namespace optique::node
