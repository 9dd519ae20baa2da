#include <exception>
#include <iostream>

#include "node/cli.h"
#include "node/gl/gl_renderer.h"

// optique-node-gl: a node that draws with OpenGL. optique-node becomes this
// program when its renderer is gl; it takes the same command line.
int main(int argc, char** argv) {
  try {
    return optique::node::run_cli(argc, argv, [](spdlog::logger& log, const std::string& capture_dir) {
      return std::make_unique<optique::node::GlRenderer>(log, capture_dir);
    });
  } catch (const std::exception& e) {
    std::cerr << "optique-node: fatal: " << e.what() << "\n";
    return 1;
  }
}
