#pragma once
// A scene's files fetched from the master chunk by chunk, without IO: which
// chunks to ask for next (a few in flight, so that the link stays busy without a
// backlog), each chunk that comes checked against the manifest — its length and
// its SHA-256 — before it may be stored, a bad one asked for again (a few times at
// most), and how far it has got. The node's protocol drives it
// (node/protocol.h); writing the files and checking each one whole is the node's
// scene cache (node/scene_cache.h).

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "clock/clock.h"
#include "optique/wire.pb.h"
#include "scene/manifest.h"

namespace optique::protocol {

// Scenes from this size on have their progress logged by quarters on both sides.
inline constexpr std::uint64_t kSceneProgressBytes = 16u << 20;

// "12.3 MiB in 0.45 s (27.3 MiB/s)", for the logs of both sides.
[[nodiscard]] std::string transfer_text(std::uint64_t bytes, clock::Nanos took);

class SceneFetch {
 public:
  static constexpr std::size_t kInFlight = 4;  // chunks asked for and not yet come
  static constexpr int kMostTries = 4;         // for one chunk: then the fetch fails

  struct Chunk {
    std::uint32_t file = 0;
    std::uint64_t index = 0;
    auto operator<=>(const Chunk&) const = default;
  };

  // What to do with a chunk that came.
  struct Verdict {
    enum class Kind { store, ask_again, fail };
    Kind kind = Kind::fail;
    std::uint32_t file = 0;
    std::uint64_t offset = 0;  // store: where its data goes in the file
    std::string problem;       // ask_again, fail: what was wrong with it
  };

  // For each file, which of its chunks are already here (a copy going on after a
  // lost connection); missing entries: none.
  using Present = std::vector<std::vector<bool>>;

  // `manifest` checked (scene::check_manifest); `scene_sha256`: its identity.
  SceneFetch(scene::SceneManifest manifest, std::string scene_sha256, const Present& present = {});

  // The requests to send now: enough to have kInFlight chunks asked for.
  [[nodiscard]] std::vector<wire::Envelope> requests();
  [[nodiscard]] Verdict take(const wire::SceneChunk& chunk);

  // Every chunk stored.
  [[nodiscard]] bool done() const { return stored_ == chunk_count_; }
  [[nodiscard]] std::uint64_t bytes_stored() const { return bytes_stored_; }
  [[nodiscard]] const scene::SceneManifest& manifest() const { return manifest_; }
  [[nodiscard]] std::uint64_t chunks_asked_again() const { return asked_again_; }

 private:
  scene::SceneManifest manifest_;
  std::string scene_sha256_;
  std::deque<Chunk> to_ask_;        // in order; chunks that failed go first
  std::map<Chunk, int> in_flight_;  // asked for, with how many times
  std::map<Chunk, int> tries_;      // how many times each chunk that failed was asked for
  std::uint64_t chunk_count_ = 0;
  std::uint64_t stored_ = 0;
  std::uint64_t bytes_stored_ = 0;
  std::uint64_t asked_again_ = 0;
};

}  // namespace optique::protocol
