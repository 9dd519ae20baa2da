#pragma once

namespace optique::master {

// The whole optique-master command line; returns the process exit status.
[[nodiscard]] int run_cli(int argc, char** argv);

}  // namespace optique::master
