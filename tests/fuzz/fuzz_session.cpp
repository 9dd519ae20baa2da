// libFuzzer entry point: an application's messages to a scene session (see run_session).

#include "fuzz_entry.h"

OPTIQUE_FUZZ_ENTRY(run_session)
