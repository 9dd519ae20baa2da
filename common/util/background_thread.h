#pragma once
// Work that must never take time from the frames (reading and decoding an
// asset while they go on) runs on a thread the scheduler favours less: on a
// machine whose cores the frame threads share, a frame is not late for it.

#include <string>

namespace optique::util {

// Lowers the calling thread's scheduling priority (Linux: its nice value, by
// `steps`, at most to 19). Returns why not, or "" when done; a thread that
// cannot be lowered still works, at the usual priority.
[[nodiscard]] std::string lower_this_threads_priority(int steps = 10);

}  // namespace optique::util
