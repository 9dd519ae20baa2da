#include "protocol/scene_fetch.h"

#include <fmt/format.h>

#include "util/sha256.h"

namespace optique::protocol {

std::string transfer_text(std::uint64_t bytes, clock::Nanos took) {
  const double mib = static_cast<double>(bytes) / (1 << 20);
  const double seconds = static_cast<double>(took) / 1e9;
  // Below a millisecond the rate says more about the clock than the link.
  if (seconds < 1e-3) return fmt::format("{:.1f} MiB at once", mib);
  return fmt::format("{:.1f} MiB in {:.2f} s ({:.1f} MiB/s)", mib, seconds, mib / seconds);
}

SceneFetch::SceneFetch(scene::SceneManifest manifest, std::string scene_sha256, const Present& present)
    : manifest_(std::move(manifest)), scene_sha256_(std::move(scene_sha256)) {
  for (std::size_t f = 0; f < manifest_.files.size(); ++f) {
    const std::uint64_t chunks = manifest_.files[f].chunks(manifest_.chunk_bytes);
    for (std::uint64_t c = 0; c < chunks; ++c) {
      if (f < present.size() && c < present[f].size() && present[f][c]) {
        ++stored_;
        bytes_stored_ += manifest_.chunk_length(f, c);
      } else {
        to_ask_.push_back({static_cast<std::uint32_t>(f), c});
      }
    }
    chunk_count_ += chunks;
  }
}

std::vector<wire::Envelope> SceneFetch::requests() {
  std::vector<wire::Envelope> out;
  while (in_flight_.size() < kInFlight && !to_ask_.empty()) {
    const Chunk chunk = to_ask_.front();
    to_ask_.pop_front();
    in_flight_[chunk] = ++tries_[chunk];
    wire::Envelope envelope;
    auto& request = *envelope.mutable_scene_request();
    request.set_scene_sha256(scene_sha256_);
    request.set_file(chunk.file);
    request.set_chunk(chunk.index);
    out.push_back(std::move(envelope));
  }
  return out;
}

SceneFetch::Verdict SceneFetch::take(const wire::SceneChunk& message) {
  const Chunk chunk{message.file(), message.chunk()};
  const auto asked = in_flight_.find(chunk);
  const std::string label = "chunk " + std::to_string(chunk.index) + " of file " + std::to_string(chunk.file);
  if (asked == in_flight_.end()) {
    return {Verdict::Kind::fail, chunk.file, 0, "the master sent " + label + ", which was not asked for"};
  }
  in_flight_.erase(asked);
  const scene::SceneFile& file = manifest_.files[chunk.file];
  const std::string& data = message.data();
  std::string problem;
  if (data.size() != manifest_.chunk_length(chunk.file, chunk.index)) {
    problem = label + " ('" + file.path + "') has " + std::to_string(data.size()) + " bytes, not " +
              std::to_string(manifest_.chunk_length(chunk.file, chunk.index));
  } else if (util::sha256_raw(data) != file.chunk_digest(chunk.index)) {
    problem = label + " ('" + file.path + "') does not match its SHA-256";
  }
  if (!problem.empty()) {
    if (tries_[chunk] >= kMostTries) {
      return {Verdict::Kind::fail, chunk.file, 0, problem + " after " + std::to_string(kMostTries) + " tries"};
    }
    to_ask_.push_front(chunk);
    ++asked_again_;
    return {Verdict::Kind::ask_again, chunk.file, 0, problem};
  }
  ++stored_;
  bytes_stored_ += data.size();
  return {Verdict::Kind::store, chunk.file, manifest_.chunk_offset(chunk.index), {}};
}

}  // namespace optique::protocol
