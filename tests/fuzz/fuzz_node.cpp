// libFuzzer entry point: one node fed what a master could send (see run_node).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_node)
