// libFuzzer entry point: a simulated cluster driven step by step (see run_protocol).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_protocol)
