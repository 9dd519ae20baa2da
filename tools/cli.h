#pragma once

namespace optique::tools {

// The whole optique-tools command line (check-config, render-reference, compose,
// calibrate; optique-master hands these subcommands over); returns the exit status.
[[nodiscard]] int run_cli(int argc, char** argv);

}  // namespace optique::tools
