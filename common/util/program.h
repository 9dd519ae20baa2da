#pragma once
// The programs optique is made of find and start each other: optique-master runs
// the tools in optique-tools and starts optique-node for --local runs;
// optique-node hands a GL node over to optique-node-gl. So the processes that
// run the frame loop and the node protocol load no image or GL library.

#include <span>
#include <string>
#include <vector>

#include "util/result.h"

namespace optique::util {

// The path of the program `name` installed beside the running one (the folder of
// /proc/self/exe), or `name` itself when that cannot be read.
[[nodiscard]] std::string sibling_program(const std::string& name);

// Replaces this process with `path` (same pid, same terminal, same signals),
// given argv[0] `name` (what its messages call it) and `args` after it. Returns
// only when it cannot.
[[nodiscard]] Error replace_process(const std::string& path, const std::string& name,
                                    std::span<const std::string> args);

// Starts `path` with `args`, waits for it, and returns its exit status (128 + the
// signal's number when a signal ended it).
[[nodiscard]] Result<int> run_program(const std::string& path, const std::vector<std::string>& args);

}  // namespace optique::util
