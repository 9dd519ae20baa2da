// libFuzzer entry point: framing and Envelope parsing (see run_frames).

#include <cstdint>
#include <cstdio>

#include "fuzz_bodies.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const optique::fuzz::Outcome outcome = optique::fuzz::run_frames({data, size});
  if (!outcome.broken.empty()) {
    std::fprintf(stderr, "optique-fuzz-frames: %s\n", outcome.broken.c_str());
    __builtin_trap();
  }
  return 0;
}
