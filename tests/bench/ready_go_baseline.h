#pragma once
// The plain ready/go barrier the issue compares against: N client processes on
// loopback TCP, the coordinator writes one byte "go" to each and waits for one
// byte "ready" back from all. Nothing else: no messages, no clock, no state. It
// runs in the same bench run as optique's barrier so the two share one machine
// state.

#include <cstddef>
#include <vector>

namespace optique::bench {

// Round times in µs, one per round, rounds paced at `rate_hz` like frames.
[[nodiscard]] std::vector<double> ready_go_rounds(std::size_t clients, std::size_t rounds, double rate_hz);

}  // namespace optique::bench
