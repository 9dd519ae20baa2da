#include "scene/manifest.h"

#include <algorithm>
#include <set>

#include "scene/relative_path.h"
#include "util/sha256.h"

namespace optique::scene {

namespace {
constexpr std::uint32_t kLeastChunkBytes = 4u << 10;
constexpr std::uint32_t kMostChunkBytes = 8u << 20;
}  // namespace

std::uint64_t SceneManifest::total_bytes() const {
  std::uint64_t total = 0;
  for (const SceneFile& file : files) total += file.size;
  return total;
}

std::uint64_t SceneManifest::chunk_length(std::size_t file, std::uint64_t index) const {
  const std::uint64_t size = files[file].size;
  const std::uint64_t offset = chunk_offset(index);
  return offset >= size ? 0 : std::min<std::uint64_t>(chunk_bytes, size - offset);
}

SceneFile describe_file(std::string path, std::string_view bytes, std::uint32_t chunk_bytes) {
  SceneFile file;
  file.path = std::move(path);
  file.size = bytes.size();
  util::Sha256 whole;
  util::Sha256 piece;
  for (std::size_t offset = 0; offset < bytes.size(); offset += chunk_bytes) {
    const std::string_view chunk = bytes.substr(offset, chunk_bytes);
    whole.update(chunk);
    piece.update(chunk);
    file.chunk_sha256 += piece.finish();
  }
  file.sha256 = whole.finish();
  return file;
}

std::string manifest_sha256(const SceneManifest& manifest) {
  // One line a file (hex, so that no path can fake a line break into the
  // digests: a path holds no '\n' once checked, and its length leads anyway).
  std::string text = "optique scene manifest 1\nchunk_bytes " + std::to_string(manifest.chunk_bytes) + "\n";
  for (const SceneFile& file : manifest.files) {
    text += std::to_string(file.path.size()) + " " + file.path + " " + std::to_string(file.size) + " " +
            util::to_hex(file.sha256) + " " + util::to_hex(file.chunk_sha256) + "\n";
  }
  return util::sha256_hex(text);
}

Result<void> check_manifest(const SceneManifest& manifest, const ManifestLimits& limits) {
  if (manifest.files.empty()) return Error{"the scene's manifest lists no file"};
  if (manifest.files.size() > limits.most_files) {
    return Error{"the scene has " + std::to_string(manifest.files.size()) + " files, more than the " +
                 std::to_string(limits.most_files) + " a node takes"};
  }
  if (manifest.chunk_bytes < kLeastChunkBytes || manifest.chunk_bytes > kMostChunkBytes) {
    return Error{"the scene's chunk size " + std::to_string(manifest.chunk_bytes) + " is not between " +
                 std::to_string(kLeastChunkBytes) + " and " + std::to_string(kMostChunkBytes) + " bytes"};
  }
  std::set<std::string> seen;
  std::uint64_t total = 0;
  for (std::size_t i = 0; i < manifest.files.size(); ++i) {
    const SceneFile& file = manifest.files[i];
    const std::string label = "the scene's file " + std::to_string(i) + " '" + file.path.substr(0, 200) + "'";
    auto path = checked_relative_path(file.path);
    if (!path) return Error{label + " " + path.error()};
    if (path.value() != file.path) return Error{label + " is not written in its plain form ('" + path.value() + "')"};
    if (!seen.insert(file.path).second) return Error{label + " is listed twice"};
    if (file.sha256.size() != util::kSha256Bytes) return Error{label + ": its SHA-256 is not 32 bytes"};
    if (file.size > limits.most_bytes || total + file.size > limits.most_bytes) {
      return Error{"the scene is larger than the " + std::to_string(limits.most_bytes) + " bytes a node takes (at " +
                   label + ")"};
    }
    total += file.size;
    if (file.chunk_sha256.size() != file.chunks(manifest.chunk_bytes) * util::kSha256Bytes) {
      return Error{label + ": " + std::to_string(file.chunk_sha256.size() / util::kSha256Bytes) +
                   " chunk digests for " + std::to_string(file.chunks(manifest.chunk_bytes)) + " chunks"};
    }
  }
  return {};
}

}  // namespace optique::scene
