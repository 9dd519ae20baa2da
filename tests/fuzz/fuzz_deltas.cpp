// libFuzzer entry point: snapshots and deltas applied to a SceneState (see run_deltas).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_deltas)
