#pragma once
// What a glTF scene is made of on disk: the file itself and every file it
// references, each with its size and SHA-256, and the SHA-256 of each of its
// chunks (the pieces in which the master sends it to a node that lacks it). The
// SHA-256 of the whole manifest is the scene's identity: the master sends it in
// every welcome, and a node loads only a scene whose manifest hashes to it.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "util/result.h"

namespace optique::scene {

// 1 MiB: a chunk and its envelope fit in the smallest message limit nodes
// accept (net::kDefaultMaxPayloadBytes), and 200 of them in flight cost little.
inline constexpr std::uint32_t kSceneChunkBytes = 1u << 20;

struct SceneFile {
  std::string path;          // inside the scene's folder ('/'-separated); files[0] is the glTF
  std::uint64_t size = 0;    // bytes
  std::string sha256;        // of the whole file, 32 raw bytes
  std::string chunk_sha256;  // 32 raw bytes for each chunk, in order

  [[nodiscard]] std::uint64_t chunks(std::uint32_t chunk_bytes) const {
    return size == 0 ? 0 : (size - 1) / chunk_bytes + 1;
  }
  // The SHA-256 of chunk `index` (32 raw bytes).
  [[nodiscard]] std::string_view chunk_digest(std::uint64_t index) const {
    return std::string_view(chunk_sha256).substr(index * 32, 32);
  }
};

struct SceneManifest {
  std::uint32_t chunk_bytes = kSceneChunkBytes;
  std::vector<SceneFile> files;

  [[nodiscard]] std::uint64_t total_bytes() const;
  // Bytes [offset, offset + length) of file `file` that chunk `index` holds.
  [[nodiscard]] std::uint64_t chunk_offset(std::uint64_t index) const { return index * chunk_bytes; }
  [[nodiscard]] std::uint64_t chunk_length(std::size_t file, std::uint64_t index) const;
};

// A file's entry: its size, its SHA-256 and its chunks'.
[[nodiscard]] SceneFile describe_file(std::string path, std::string_view bytes,
                                      std::uint32_t chunk_bytes = kSceneChunkBytes);

// The scene's identity: SHA-256 (hex) of the manifest written out in one fixed
// way (every path, size and digest, the chunk size).
[[nodiscard]] std::string manifest_sha256(const SceneManifest& manifest);

// Limits on what a node takes from a master.
struct ManifestLimits {
  std::uint64_t most_bytes = 0;  // all files together
  std::size_t most_files = 4096;
};
// What any scene may be: the master refuses a larger one when it loads it, a
// node a larger manifest when it decodes the welcome (and its own
// --max-scene-mb after that).
inline constexpr ManifestLimits kLargestScene{std::uint64_t{1} << 40, std::size_t{1} << 16};

// A manifest from a peer, checked before anything is fetched or written: at
// least one file, every path inside the folder (scene/relative_path.h) and
// unique, digests of the right length, a chunk size between 4 KiB and 8 MiB,
// within `limits`. The error names the file.
[[nodiscard]] Result<void> check_manifest(const SceneManifest& manifest, const ManifestLimits& limits);

}  // namespace optique::scene
