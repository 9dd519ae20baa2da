// libFuzzer entry point: head tracker datagrams parsed and taken (see run_tracker).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_tracker)
