#pragma once
// The bodies of the fuzz targets, shared by the libFuzzer entry points (clang,
// OPTIQUE_FUZZ=ON) and the corpus replay test (every build): the replay keeps the
// bodies compiling and the corpus passing where no clang is installed.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace optique::fuzz {

// Largest payload the frame target accepts: small enough that an oversized
// header is cheap to reach, large enough for any real Envelope.
inline constexpr std::uint32_t kMaxPayloadBytes = 1u << 20;

// Splits the delta target's input into a Snapshot and the deltas that follow it.
// As a tag, four 0xfb bytes would start a field number no message here has, so it
// turns up only inside doubles or bytes (the seed generator checks that none of its
// chunks holds it); a mutated chunk that does just splits differently. A separator
// rather than length prefixes, so that a mutation inside one chunk leaves the
// others intact.
inline constexpr std::string_view kChunkSeparator{"\xfb\xfb\xfb\xfb", 4};

// What a body saw: `broken` names the first invariant that failed (empty when all
// held); the counters let the replay test check that the corpus reaches the
// interesting paths and is not, say, all garbage.
struct Outcome {
  std::string broken;
  int good_frames = 0;
  int envelopes = 0;       // good frames that parsed as an Envelope with a body
  int deltas_applied = 0;  // deltas that apply_delta accepted
  int deltas_refused = 0;  // parsed deltas that apply_delta refused
  bool snapshot_accepted = false;
};

// Input: byte 0 picks how the rest is cut into fragments (0: all at once, 1: byte
// by byte, n: pseudo-random pieces of 1..n bytes); the rest is a byte stream of
// frames fed to a FrameReader, and every good payload to parse_envelope.
[[nodiscard]] Outcome run_frames(std::span<const std::uint8_t> input);

// Input: a serialized wire::Snapshot, then any number of serialized
// wire::StateDelta, separated by kChunkSeparator. The snapshot seeds a SceneState
// (a first chunk that does not decode or that from_snapshot refuses means the
// default state, so such inputs still reach the deltas); the deltas apply one after
// the other.
[[nodiscard]] Outcome run_deltas(std::span<const std::uint8_t> input);

}  // namespace optique::fuzz
