// libFuzzer entry point: framing and Envelope parsing (see run_frames).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_frames)
