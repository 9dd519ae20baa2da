#pragma once
// A shipped or written config run as a local cluster (optique-master --local,
// real GL node processes) that captures frames, and its captures read back: what
// gpu tests compare.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "image/image.h"
#include "scratch.h"

namespace optique::testing {

// A run's output folder, in a scratch folder that goes with the value (kept
// when the test has failed by then).
struct CapturedRun {
  std::unique_ptr<ScratchDir> folder;
  std::string out;
  operator const std::string&() const { return out; }  // NOLINT: where an output folder is
};

// The command line of a master that runs `config` with local GL nodes for
// `frames` frames, capturing every `capture_every`-th, writing into `out`,
// `extra` arguments after.
[[nodiscard]] std::vector<std::string> capturing_master(const std::string& config, int frames, int capture_every,
                                                        const std::string& out,
                                                        const std::vector<std::string>& extra = {});

// Runs `config` for `frames` frames, capturing every `capture_every`-th, with
// `extra` arguments for the master; expects it to succeed and returns its
// output folder (in a fresh temporary folder).
[[nodiscard]] CapturedRun run_and_capture(const std::string& config, int frames, int capture_every,
                                          const std::vector<std::string>& extra = {});

// What node `projector` captured of `frame` (the projector's signal, PNG).
[[nodiscard]] image::FloatImage capture(const std::string& out, const std::string& projector, std::uint64_t frame);

}  // namespace optique::testing
