#pragma once

namespace optique::node {

// The whole optique-node command line; returns the process exit status.
[[nodiscard]] int run_cli(int argc, char** argv);

}  // namespace optique::node
