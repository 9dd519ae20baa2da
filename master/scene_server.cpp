#include "master/scene_server.h"

#include <fmt/format.h>

#include <algorithm>

#include "protocol/scene_fetch.h"

namespace optique::master {

SceneServer::SceneServer(const scene::LoadedScene& scene) : scene_(scene) {}

// A node without a copy of the scene asks for its files chunk by chunk while it
// sets up: each request that names a chunk of this scene is answered from the
// bytes the master loaded (scene_load/gltf_source.h: what it hashed), and gives the
// node another configure_timeout() to finish.
void SceneServer::request(PeerId peer, const std::string& id, SceneServed& served, const wire::SceneRequest& request,
                          clock::Nanos now, Actions& out) const {
  const scene::SceneManifest& manifest = scene_.manifest;
  if (manifest.files.empty() || request.scene_sha256() != scene_.content_sha256) {
    out.push_back(Close{peer, "asked for the files of another scene"});
    return;
  }
  if (request.file() >= manifest.files.size() ||
      request.chunk() >= manifest.files[request.file()].chunks(manifest.chunk_bytes)) {
    out.push_back(Close{peer, "asked for chunk " + std::to_string(request.chunk()) + " of file " +
                                  std::to_string(request.file()) + ", which the scene does not have"});
    return;
  }
  const std::uint64_t total = manifest.total_bytes();
  if (!served.sending) {
    served.sending.emplace();
    served.sending->started = now;
    out.push_back(
        Log{spdlog::level::info, fmt::format("sending the scene to '{}', which has no copy: {} file(s), {:.1f} MiB", id,
                                             manifest.files.size(), static_cast<double>(total) / (1 << 20))});
  }
  SceneSending& sending = *served.sending;
  const std::uint64_t offset = manifest.chunk_offset(request.chunk());
  const std::uint64_t length = manifest.chunk_length(request.file(), request.chunk());
  sending.bytes_asked += length;
  if (sending.bytes_asked > kMostSceneRepeats * std::max<std::uint64_t>(total, manifest.chunk_bytes)) {
    out.push_back(Close{peer, "asked for the scene " + std::to_string(kMostSceneRepeats) + " times over"});
    return;
  }
  if (sending.sent.insert({request.file(), request.chunk()}).second) {
    sending.bytes_new += length;
  } else if (++sending.repeats <= kRepeatsLogged) {
    // What a node asks for twice came spoilt (or not at all) the first time.
    out.push_back(Log{spdlog::level::warn,
                      fmt::format("'{}' asked again for chunk {} of '{}' of the scene (spoilt on the way?){}", id,
                                  request.chunk(), manifest.files[request.file()].path,
                                  sending.repeats == kRepeatsLogged ? "; further repeats are not logged" : "")});
  }
  wire::Envelope envelope;
  auto& chunk = *envelope.mutable_scene_chunk();
  chunk.set_file(request.file());
  chunk.set_chunk(request.chunk());
  chunk.set_data(scene_.files[request.file()]->data() + offset, length);
  out.push_back(Send{peer, std::move(envelope)});
  out.push_back(SetDeadline{peer, configure_timeout(),
                            "node did not finish configuring within " + std::to_string(configure_timeout().count()) +
                                " s of its last request for the scene"});
  const int quarters = static_cast<int>(4 * sending.bytes_new / std::max<std::uint64_t>(total, 1));
  if (quarters > sending.quarters_logged) {
    sending.quarters_logged = quarters;
    if (quarters == 4) {
      out.push_back(Log{spdlog::level::info, fmt::format("sent the scene to '{}': {}", id,
                                                         protocol::transfer_text(total, now - sending.started))});
    } else if (total >= protocol::kSceneProgressBytes) {
      out.push_back(Log{spdlog::level::info, fmt::format("sending the scene to '{}': {} %", id, 25 * quarters)});
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
  const scene::SceneManifest& manifest = scene_.manifest;
  if (manifest.files.empty() || wait.scene_sha256() != scene_.content_sha256) {
    out.push_back(Close{peer, "waited for another scene"});
    return;
  }
  const std::chrono::seconds longest = 2 * configure_timeout();
  if (served.waiting_since && now - *served.waiting_since > clock::nanos(longest)) {
    out.push_back(Close{
        peer, "waited for another node's copy of the scene for more than " + std::to_string(longest.count()) + " s"});
    return;
  }
  const std::uint64_t total = manifest.total_bytes();
  if (!served.waiting_since) {
    served.waiting_since = now;
    out.push_back(Log{spdlog::level::info,
                      fmt::format("'{}' waits for the copy of the scene another node of its host is fetching into "
                                  "the cache they share ({:.1f} of {:.1f} MiB there)",
                                  id, static_cast<double>(std::min(wait.bytes_there(), total)) / (1 << 20),
                                  static_cast<double>(total) / (1 << 20))});
  }
  out.push_back(SetDeadline{peer, configure_timeout(),
                            "node did not finish configuring within " + std::to_string(configure_timeout().count()) +
                                " s of saying it waits for the scene"});
}

std::chrono::seconds SceneServer::configure_timeout() const {
  const std::uint64_t bytes = scene_.manifest.total_bytes();
  return kConfigureTimeout + std::chrono::seconds((bytes + kSceneBytesPerExtraSecond - 1) / kSceneBytesPerExtraSecond);
}

}  // namespace optique::master
