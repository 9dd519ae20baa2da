// libFuzzer entry point: snapshots and deltas applied to a SceneState (see run_deltas).

#include <cstdint>
#include <cstdio>

#include "fuzz_bodies.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const optique::fuzz::Outcome outcome = optique::fuzz::run_deltas({data, size});
  if (!outcome.broken.empty()) {
    std::fprintf(stderr, "optique-fuzz-deltas: %s\n", outcome.broken.c_str());
    __builtin_trap();
  }
  return 0;
}
