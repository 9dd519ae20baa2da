#pragma once
// The scene session's rules (master.api), with no socket: an application's
// connection is greeted with a Challenge as a node's is, answers with a Hello
// naming itself (capability "scene-session"; with the installation's shared
// secret, its MAC, and every message after it sealed), then sends requests;
// each transaction is applied to the live scene (live_scene.h) and answered
// with the frame from which every node shows it, or why it was refused; the
// events it subscribed to are sent as they happen. The master's shell carries
// out the actions on its connections.

#include <spdlog/common.h>

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "clock/clock.h"
#include "master/session/live_scene.h"
#include "net/auth.h"
#include "net/session_seal.h"
#include "optique/wire.pb.h"

namespace optique::master {

using SessionId = std::uint64_t;

namespace session_action {
struct Send {
  SessionId session = 0;
  wire::Envelope message;
};
// Close the connection; `after_sending`: once what is queued has gone (a refusal).
struct Close {
  SessionId session = 0;
  std::string reason;
  bool after_sending = false;
};
// The largest message the application may send from now on.
struct SetMaxPayload {
  SessionId session = 0;
  std::uint32_t bytes = 0;
};
// Seal everything from now on (net/session_seal.h).
struct Protect {
  SessionId session = 0;
  net::SessionKeys keys;
};
// Append this entry to the journal (journal.h); comes before the reply that
// tells the application its transaction was applied.
struct Journal {
  std::string entry;
};
struct Log {
  spdlog::level::level_enum level = spdlog::level::info;
  std::string text;
};
// Load asset `asset` (off the io thread): the glTF file at `path` (absolute,
// inside master.api.assets by its words; the shell checks it resolves there),
// or the binary glTF `glb`. Answer with asset_loaded() or asset_failed().
struct LoadAsset {
  std::string asset;
  std::string path;
  std::string glb;
};
}  // namespace session_action

using SessionAction =
    std::variant<session_action::Send, session_action::Close, session_action::SetMaxPayload, session_action::Protect,
                 session_action::Journal, session_action::Log, session_action::LoadAsset>;
using SessionActions = std::vector<SessionAction>;

// The capability an application's Hello names.
inline constexpr const char* kSceneSessionCapability = "scene-session";

struct SceneSessionSettings {
  std::size_t max_sessions = 16;
  // What an application may send once it has said hello (a transaction's
  // size); before, only what a hello needs.
  std::uint32_t max_message_bytes = 16u << 20;
  // Applications must prove they hold it; without one only loopback peers are accepted.
  std::optional<net::Secret> secret;
  // Journal every transaction applied (the master's --record).
  bool journal = false;
  // An application with more than this waiting to be sent to it (the kernel's
  // send buffer aside) for longer than `stalled_for` has stopped reading: it
  // is closed, so that its events do not pile up without end. A slow link
  // that drains a large reply within that time is not.
  std::size_t max_queued_bytes = 1u << 20;
  std::chrono::nanoseconds stalled_for = std::chrono::seconds(5);
  // LoadAsset's paths are in this folder (absolute; master.api.assets).
  std::string assets_folder;
  // Assets loading at once (read, checked, sent to every node): more are refused.
  std::size_t max_loading = 4;
};

class SceneSessions {
 public:
  // `live` must outlive it.
  SceneSessions(LiveScene& live, SceneSessionSettings settings) : live_(live), settings_(std::move(settings)) {}

  // A connection from `peer_text` (loopback: from this machine); `nonce`: fresh
  // randomness for its challenge (net::random_nonce()).
  [[nodiscard]] SessionActions accepted(SessionId session, const std::string& peer_text, bool loopback,
                                        const std::vector<std::uint8_t>& nonce);
  // An application the operator's server let in by its own rules (its
  // WebSocket, /api/session): no challenge and no hello; `application` is the
  // name it gave. Refused like any other when it names itself wrongly or when
  // the master holds as many sessions as it may.
  [[nodiscard]] SessionActions opened(SessionId session, const std::string& peer_text, const std::string& application);
  // `next_frame`: the frame the master begins next, which shows what is applied now.
  [[nodiscard]] SessionActions message(SessionId session, const wire::Envelope& message, std::uint64_t next_frame);
  // A request from an application opened() (the binary port's come in message()).
  [[nodiscard]] SessionActions request(SessionId session, const session::Request& request, std::uint64_t next_frame);
  // A message from an application opened() that is no Request: it is told
  // why, and the session goes on.
  [[nodiscard]] SessionActions unreadable(SessionId session, const std::string& reason) const;
  [[nodiscard]] SessionActions closed(SessionId session, const std::string& reason);
  // `event` sent to every application that subscribed to its kind.
  [[nodiscard]] SessionActions publish(const session::Event& event) const;
  // How much waits to be sent to `session` at `now` (after an event was
  // queued for it): closes it when it has stopped reading.
  [[nodiscard]] SessionActions queued(SessionId session, std::size_t bytes, clock::Nanos now);
  // The asset a LoadAsset asked for is on every node in the frames from
  // `frame` on, read from `path` (absolute) with identity `sha256`: the live
  // scene takes it (`animated`: it has animations), the journal records it,
  // and the application that asked hears Applied.
  [[nodiscard]] SessionActions asset_loaded(const std::string& asset, std::uint64_t frame, bool animated,
                                            const std::string& path, const std::string& sha256);
  // It could not be loaded: the application that asked hears why (`field`:
  // "load_asset.path", "load_asset.glb"; the reason names the node when one failed).
  [[nodiscard]] SessionActions asset_failed(const std::string& asset, const std::string& field,
                                            const std::string& reason);

  [[nodiscard]] std::size_t open() const { return sessions_.size(); }

 private:
  struct Session {
    std::string peer_text;
    std::vector<std::uint8_t> nonce;
    std::string application;  // from its hello; empty before
    bool refused = false;
    session::Subscribe subscribed;           // the events it takes
    std::optional<clock::Nanos> over_since;  // when its queue went over max_queued_bytes
  };

  void on_hello(SessionId id, Session& session, const wire::Envelope& message, SessionActions& out);
  // Whether `id` is a session past its hello (or opened) and not refused: one that may be answered.
  [[nodiscard]] bool answerable(SessionId id) const;
  // Whether the master may hold one more session; refused if not.
  bool admit(SessionId id, Session& session, SessionActions& out);
  void connected(Session& session, const std::string& application, SessionActions& out);
  void refuse(SessionId id, Session& session, const std::string& reason, bool retriable, SessionActions& out);
  void on_request(SessionId id, const session::Request& request, std::uint64_t next_frame, SessionActions& out);
  // Checks a LoadAsset; the field and reason it is refused for, if so.
  [[nodiscard]] std::optional<std::pair<std::string, std::string>> load_problem(const session::LoadAsset& load) const;

  LiveScene& live_;
  SceneSessionSettings settings_;
  std::map<SessionId, Session> sessions_;
  // Assets loading: who asked (the session may have gone since).
  struct Asking {
    SessionId session = 0;
    std::uint64_t request = 0;
  };
  std::map<std::string, Asking> loading_;
};

}  // namespace optique::master
