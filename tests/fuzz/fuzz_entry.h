#pragma once
// One libFuzzer entry point per binary: OPTIQUE_FUZZ_ENTRY(run_frames) makes the
// binary run that body on each input and trap, naming the broken invariant.

#include <cstdint>
#include <cstdio>

#include "fuzz_bodies.h"

#define OPTIQUE_FUZZ_ENTRY(body)                                                      \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    const optique::fuzz::Outcome outcome = optique::fuzz::body({data, size});         \
    if (!outcome.broken.empty()) {                                                    \
      std::fprintf(stderr, "optique-fuzz: " #body ": %s\n", outcome.broken.c_str());  \
      __builtin_trap();                                                               \
    }                                                                                 \
    return 0;                                                                         \
  }
