#include "master/scene_server.h"

#include <fmt/format.h>

#include <algorithm>
#include <cassert>

#include "protocol/scene_fetch.h"

namespace optique::master {

SceneServer::SceneServer(const scene::LoadedScene& scene) : scene_(scene) {}

void SceneServer::add(const std::string& id, std::shared_ptr<const scene::LoadedScene> asset) {
  assert(asset && !asset->content_sha256.empty());
  const std::string sha256 = asset->content_sha256;
  assets_[sha256] = Asset{id, std::move(asset)};
}

std::pair<const scene::LoadedScene*, std::string> SceneServer::find(const std::string& sha256) const {
  if (sha256.empty()) return {nullptr, ""};
  if (sha256 == scene_.content_sha256) return {&scene_, "the scene"};
  const auto found = assets_.find(sha256);
  if (found == assets_.end()) return {nullptr, ""};
  return {found->second.scene.get(), "the asset '" + found->second.id + "'"};
}

// A node without a copy of the scene asks for its files chunk by chunk while it
// sets up: each request that names a chunk of this scene is answered from the
// bytes the master loaded (scene_load/gltf_source.h: what it hashed), and gives the
// node another configure_timeout() to finish.
void SceneServer::request(PeerId peer, const std::string& id, SceneServed& served, const wire::SceneRequest& request,
                          bool setting_up, clock::Nanos now, Actions& out) const {
  const auto [scene, what] = find(request.scene_sha256());
  if (scene == nullptr || scene->manifest.files.empty()) {
    out.push_back(Close{peer, "asked for the files of another scene"});
    return;
  }
  if (!setting_up && scene == &scene_) {
    out.push_back(Close{peer, "asked for the scene's files after setting up"});
    return;
  }
  const scene::SceneManifest& manifest = scene->manifest;
  if (request.file() >= manifest.files.size() ||
      request.chunk() >= manifest.files[request.file()].chunks(manifest.chunk_bytes)) {
    out.push_back(Close{peer, "asked for chunk " + std::to_string(request.chunk()) + " of file " +
                                  std::to_string(request.file()) + ", which the scene does not have"});
    return;
  }
  const std::uint64_t total = manifest.total_bytes();
  // Kept for each scene and asset the node asks for over its connection, so
  // that asking for two by turns does not reset what it has asked for.
  auto [at, first_request] = served.sending.try_emplace(scene->content_sha256);
  if (first_request) {
    at->second.started = now;
    out.push_back(
        Log{spdlog::level::info, fmt::format("sending {} to '{}', which has no copy: {} file(s), {:.1f} MiB", what, id,
                                             manifest.files.size(), static_cast<double>(total) / (1 << 20))});
  }
  SceneSending& sending = at->second;
  const std::uint64_t offset = manifest.chunk_offset(request.chunk());
  const std::uint64_t length = manifest.chunk_length(request.file(), request.chunk());
  sending.bytes_asked += length;
  if (sending.bytes_asked > kMostSceneRepeats * std::max<std::uint64_t>(total, manifest.chunk_bytes)) {
    out.push_back(Close{peer, "asked for " + what + " " + std::to_string(kMostSceneRepeats) + " times over"});
    return;
  }
  if (sending.sent.insert({request.file(), request.chunk()}).second) {
    sending.bytes_new += length;
  } else if (++sending.repeats <= kRepeatsLogged) {
    // What a node asks for twice came spoilt (or not at all) the first time.
    out.push_back(Log{spdlog::level::warn,
                      fmt::format("'{}' asked again for chunk {} of '{}' of {} (spoilt on the way?){}", id,
                                  request.chunk(), manifest.files[request.file()].path, what,
                                  sending.repeats == kRepeatsLogged ? "; further repeats are not logged" : "")});
  }
  wire::Envelope envelope;
  auto& chunk = *envelope.mutable_scene_chunk();
  chunk.set_file(request.file());
  chunk.set_chunk(request.chunk());
  chunk.set_data(scene->files[request.file()]->data() + offset, length);
  out.push_back(Send{peer, std::move(envelope)});
  // In the frames, the node's liveness and its own stall check bound a fetch.
  if (setting_up) {
    out.push_back(SetDeadline{peer, configure_timeout(),
                              "node did not finish configuring within " + std::to_string(configure_timeout().count()) +
                                  " s of its last request for " + what});
  }
  const int quarters = static_cast<int>(4 * sending.bytes_new / std::max<std::uint64_t>(total, 1));
  if (quarters > sending.quarters_logged) {
    sending.quarters_logged = quarters;
    if (quarters == 4) {
      out.push_back(Log{spdlog::level::info, fmt::format("sent {} to '{}': {}", what, id,
                                                         protocol::transfer_text(total, now - sending.started))});
    } else if (total >= protocol::kSceneProgressBytes) {
      out.push_back(Log{spdlog::level::info, fmt::format("sending {} to '{}': {} %", what, id, 25 * quarters)});
    }
  }
}

// A node whose host has another node fetching the scene into the cache they
// share waits for that copy: each word that it still waits gives it another
// configure_timeout(), as a request would (the node gives up waiting, and
// fetches, once the other copy stops growing), up to twice that in all: time
// for a whole fetch at the rate configure_timeout() allows for.
void SceneServer::wait(PeerId peer, const std::string& id, SceneServed& served, const wire::SceneWait& wait,
                       clock::Nanos now, Actions& out) const {
  const auto [scene, what] = find(wait.scene_sha256());
  if (scene == nullptr || scene->manifest.files.empty()) {
    out.push_back(Close{peer, "waited for another scene"});
    return;
  }
  const scene::SceneManifest& manifest = scene->manifest;
  const std::chrono::seconds longest = 2 * configure_timeout();
  if (served.waiting_since && now - *served.waiting_since > clock::nanos(longest)) {
    out.push_back(Close{peer, "waited for another node's copy of " + what + " for more than " +
                                  std::to_string(longest.count()) + " s"});
    return;
  }
  const std::uint64_t total = manifest.total_bytes();
  if (!served.waiting_since) {
    served.waiting_since = now;
    out.push_back(Log{spdlog::level::info,
                      fmt::format("'{}' waits for the copy of {} another node of its host is fetching into "
                                  "the cache they share ({:.1f} of {:.1f} MiB there)",
                                  id, what, static_cast<double>(std::min(wait.bytes_there(), total)) / (1 << 20),
                                  static_cast<double>(total) / (1 << 20))});
  }
  out.push_back(SetDeadline{peer, configure_timeout(),
                            "node did not finish configuring within " + std::to_string(configure_timeout().count()) +
                                " s of saying it waits for " + what});
}

std::chrono::seconds SceneServer::configure_timeout() const {
  std::uint64_t bytes = scene_.manifest.total_bytes();
  for (const auto& [sha256, asset] : assets_) bytes += asset.scene->manifest.total_bytes();
  return kConfigureTimeout + std::chrono::seconds((bytes + kSceneBytesPerExtraSecond - 1) / kSceneBytesPerExtraSecond);
}

}  // namespace optique::master
