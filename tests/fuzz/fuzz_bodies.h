#pragma once
// The bodies of the fuzz targets, shared by the libFuzzer entry points (clang,
// OPTIQUE_FUZZ=ON) and the corpus replay test (every build): the replay keeps the
// bodies compiling and the corpus passing where no clang is installed.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "scene/manifest.h"

#if __has_include(<google/protobuf/stubs/logging.h>)
#include <google/protobuf/stubs/logging.h>
#define OPTIQUE_FUZZ_HAS_LOG_SILENCER 1
#endif

// A failed invariant returns its own text and place from the checking function,
// so a crash report (or a replay failure) says which one without a debugger.
#define OPTIQUE_FUZZ_REQUIRE(cond)                                                                        \
  do {                                                                                                    \
    if (!(cond)) {                                                                                        \
      return std::string("invariant " #cond " (") + __FILE_NAME__ + ":" + std::to_string(__LINE__) + ")"; \
    }                                                                                                     \
  } while (false)

namespace optique::fuzz {

// Protobuf logs an error for every string field that is not UTF-8: expected for
// fuzz input, and enough of them to bury a real report.
struct QuietProtobuf {
#ifdef OPTIQUE_FUZZ_HAS_LOG_SILENCER
  google::protobuf::LogSilencer silencer;
#endif
};

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
  int frames_presented = 0;            // run_protocol: by all nodes; run_node: by the node
  int renders = 0;                     // run_node: frames the node drew
  int closes = 0;                      // run_node: messages that made it close or stop
  int configured = 0;                  // run_node: times the node set its renderer up
  int scene_chunks = 0;                // run_node: chunks of a scene's files it stored
  int assets_readied = 0;              // run_node: assets offered in the frames it readied
  scene::SceneManifest scene_files{};  // run_node: the scene being fetched
  bool finished = false;               // run_protocol: the master's run ended
  int datagrams_parsed = 0;            // run_tracker: datagrams parse_dtrack took
  int samples = 0;                     // run_tracker: samples the head tracker took
  int applied = 0;                     // run_session: transactions the live scene took
  int refused = 0;                     // run_session: transactions it refused
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

// Input: byte 0 sets how many frames the master runs (5 … 44), byte 1 at which
// frame the first node's state is corrupted (0: never); each further byte is one
// step of a simulated cluster (tests/support/sim_cluster.h: which message
// arrives, which timer fires, which link breaks, an interrupt). Then the network
// turns prompt until the run ends. Invariants: the cluster's (no action for a
// peer the master knows is gone, no frame shown twice or out of order, none
// skipped after a join, a repaired state right the next frame, no swap without
// a ready), and the run ends.
[[nodiscard]] Outcome run_protocol(std::span<const std::uint8_t> input);

// Input: chunks separated by kChunkSeparator. The first is a serialized
// wire::Welcome (if it does not parse, a good one for the 2×2 wall) that a node
// in the handshake receives; if it takes the job, a snapshot joins it, and every
// further chunk arrives as a serialized wire::Envelope. Invariants: a job that
// is taken is sane (finite geometry, sizes > 0); every frame drawn has a state,
// lights the scene has (ascending), a finite focus; garbage closes the
// connection, it never crashes the node.
[[nodiscard]] Outcome run_node(std::span<const std::uint8_t> input);

// Input: UDP datagrams from a head tracker, separated by kChunkSeparator; each
// chunk's first byte is the gap before it in tenths of a millisecond, the rest
// the datagram. Each goes to parse_dtrack and to a HeadTracker (body 0, each
// prediction in turn), which is asked for the head a frame on. Invariants: a
// parsed body's numbers are finite and its matrix a rotation; the head is finite,
// its turn a unit quaternion; every datagram is counted once (taken, malformed,
// without the body, backwards or flood).
[[nodiscard]] Outcome run_tracker(std::span<const std::uint8_t> input);

// Input: serialized wire::Envelopes from an application, separated by
// kChunkSeparator, to a scene session past its hello (a chunk that does not parse
// is skipped, as a connection would close on it; a chunk of one byte begins a
// frame). Invariants: every request is answered once, with its id, or the session
// is closed; the live scene stays whole (every parent there, the children index
// its parents', the chains and the count within their limits); and the state a
// frame makes of it is one a node accepts, through a snapshot and a delta.
[[nodiscard]] Outcome run_session(std::span<const std::uint8_t> input);

}  // namespace optique::fuzz
