#pragma once
// The seed corpus, as code: optique-fuzz-corpus writes it to tests/fuzz/corpus/,
// where it is committed; the replay test also runs the bodies over it in memory, so
// this code keeps compiling and its seeds keep passing.

#include <cstdint>
#include <string>
#include <vector>

namespace optique::fuzz {

struct Seed {
  std::string name;  // file name in the corpus folder
  std::vector<std::uint8_t> bytes;
};

// Inputs for run_frames (byte 0 picks the fragmentation, see fuzz_bodies.h).
[[nodiscard]] std::vector<Seed> frame_seeds();

// Inputs for run_deltas: a Snapshot and deltas, joined by kChunkSeparator.
[[nodiscard]] std::vector<Seed> delta_seeds();

// Inputs for run_protocol: frames, corruption, then one step per byte.
[[nodiscard]] std::vector<Seed> protocol_seeds();

// Inputs for run_node: a Welcome, then Envelopes, joined by kChunkSeparator.
[[nodiscard]] std::vector<Seed> node_seeds();

// Inputs for run_tracker: a gap byte and a datagram each, joined by kChunkSeparator.
[[nodiscard]] std::vector<Seed> tracker_seeds();

// Inputs for run_session: an application's Envelopes (a one-byte chunk: the next
// frame), joined by kChunkSeparator.
[[nodiscard]] std::vector<Seed> session_seeds();

}  // namespace optique::fuzz
