#pragma once
// Serving a glTF scene's files to the nodes that have no copy (the node's side:
// node/scene_fetching.cpp): each request for a chunk of this scene is answered
// from the bytes the master loaded and hashed, and gives the node more time to
// set up; a node that waits for another node of its host to fetch the scene
// into the cache they share is given time too, up to a limit. One unit the
// master's core dispatches SceneRequest and SceneWait to; it answers in the
// core's actions (master/actions.h).

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "clock/clock.h"
#include "master/actions.h"
#include "optique/wire.pb.h"
#include "scene_load/load_scene.h"

namespace optique::master {

// How long a node may take to set itself up (GL context, scene) after the welcome,
// or after the last chunk of the scene it asks for: this, and a second more for
// every kSceneBytesPerExtraSecond of a glTF scene's files (which a node reads and
// hashes once or twice while it sets up: 8 GiB is 158 s in all).
inline constexpr std::chrono::seconds kConfigureTimeout{30};
inline constexpr std::uint64_t kSceneBytesPerExtraSecond = 64u << 20;
// A node that asks for more than this many times the scene's bytes is broken.
inline constexpr std::uint64_t kMostSceneRepeats = 4;

// Sending one node the files of one scene or asset (from its first request).
struct SceneSending {
  clock::Nanos started = 0;
  std::uint64_t bytes_asked = 0;  // all chunks sent, repeats included
  std::uint64_t bytes_new = 0;    // each chunk once
  std::set<std::pair<std::uint32_t, std::uint64_t>> sent;
  int quarters_logged = 0;
  int repeats = 0;  // chunks asked for again
};

// What one node has been served: the bookkeeping a session keeps.
struct SceneServed {
  std::map<std::string, SceneSending> sending;  // by the scene's or asset's SHA-256
  // Since when it waits for another node's copy of the scene (SceneWait).
  std::optional<clock::Nanos> waiting_since;
};

class SceneServer {
 public:
  // Keeps a reference: `scene` must outlive it.
  explicit SceneServer(const scene::LoadedScene& scene);

  // Serves an asset an application loaded too (by its content_sha256), from
  // now on; a node asks for its chunks while it sets up or while frames go on.
  void add(const std::string& id, std::shared_ptr<const scene::LoadedScene> asset);
  void remove(const std::string& sha256) { assets_.erase(sha256); }

  // How long a node may take to set up, from its welcome or its last word
  // about the scene (kConfigureTimeout and a second per 64 MiB of files).
  [[nodiscard]] std::chrono::seconds configure_timeout() const;
  // `node`: its projector's id, for the log. `setting_up`: the node has not
  // yet joined the frames (each request gives it more time to set up); a
  // node in the frames may ask only for an asset's files.
  void request(PeerId peer, const std::string& node, SceneServed& served, const wire::SceneRequest& request,
               bool setting_up, clock::Nanos now, Actions& out) const;
  void wait(PeerId peer, const std::string& node, SceneServed& served, const wire::SceneWait& wait, clock::Nanos now,
            Actions& out) const;

 private:
  static constexpr int kRepeatsLogged = 10;
  struct Asset {
    std::string id;
    std::shared_ptr<const scene::LoadedScene> scene;
  };
  // The scene or asset with these files, and how the log names it; null: none.
  [[nodiscard]] std::pair<const scene::LoadedScene*, std::string> find(const std::string& sha256) const;
  const scene::LoadedScene& scene_;
  std::map<std::string, Asset> assets_;  // by content_sha256
};

}  // namespace optique::master
