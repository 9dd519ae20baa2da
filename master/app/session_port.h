#pragma once
// The scene session's Asio shell (master.api): the port applications connect
// to, their connections, and what SceneSessions (master/session) decides
// carried out on them. It holds the live scene the frame loop reads.

#include <spdlog/logger.h>
#include <boost/asio.hpp>

#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "config/installation.h"
#include "http/websocket.h"
#include "master/actions.h"
#include "master/app/journal_file.h"
#include "master/app/tcp_listener.h"
#include "master/session/live_scene.h"
#include "master/session/scene_sessions.h"
#include "net/connection.h"
#include "scene_load/load_scene.h"
#include "util/result.h"

namespace optique::master {

class SessionPort {
 public:
  // Applications edit `live` (which the frame loop reads: RunSettings::live;
  // it must outlive this); with `journal`, each transaction applied is
  // appended to it before the application hears so.
  // An asset an application uploaded is kept in `uploads` (made when first
  // needed), by its SHA-256: beside the journal, so that a restart finds it;
  // without a journal, a folder of this run's own, removed when the port goes.
  struct Uploads {
    std::string folder;
    bool for_this_run_only = false;
  };
  SessionPort(asio::io_context& io, const config::ApiServer& settings, LiveScene& live,
              std::optional<JournalFile> journal, std::optional<net::Secret> secret, std::uint32_t max_message_bytes,
              Uploads uploads, spdlog::logger& log);
  ~SessionPort();
  SessionPort(const SessionPort&) = delete;
  SessionPort& operator=(const SessionPort&) = delete;
  // Where an asset an application loaded goes once it is read and checked
  // (off this thread; the hook runs on it): the master offers it to the nodes,
  // then says asset_usable() or asset_unusable().
  using AssetLoaded = std::function<void(const std::string& id, std::shared_ptr<const scene::LoadedScene> asset)>;
  void on_asset_loaded(AssetLoaded hook) { asset_loaded_ = std::move(hook); }
  // After each request an application sent (on this thread): the master
  // stages what it changed in the live scene to the nodes.
  void on_request_handled(std::function<void()> hook) { request_handled_ = std::move(hook); }
  // Every node in the frames has the asset from frame `frame` on: the live
  // scene takes it, the journal records it, the application hears so.
  void asset_usable(const AssetUsable& usable);
  // A node cannot draw it: the application hears why.
  void asset_unusable(const std::string& id, const std::string& reason);
  // Listens and accepts; `next_frame` says which frame the master begins next.
  // The port bound.
  [[nodiscard]] Result<std::uint16_t> start(std::function<std::uint64_t()> next_frame);
  // What becomes of a WebSocket to the operator's /api/session from
  // `peer_text`, named `application`: a scene session like the port's, in
  // JSON (master/session/session_json.h). Called on the operator server's
  // thread, which has checked who may open one; the session lives on this
  // port's thread.
  [[nodiscard]] std::shared_ptr<http::WebSocketEndpoint> websocket(const std::string& application,
                                                                   const std::string& peer_text);
  // Sends `event` to the applications that subscribed to its kind. One that
  // has more than max_queued_bytes waiting (it stopped reading) is closed:
  // it never holds the frames back.
  void publish(const session::Event& event);
  // No more sessions; the open ones are told goodbye.
  void close(const std::string& reason);
  // Held while a barrier round is under way: no request is read or handled
  // and no event sent, so that neither the master's thread nor an application
  // woken by an event competes with the nodes for the round (the round is what
  // every frame waits for; an application is answered a few hundred
  // microseconds later). Let go, what waited goes on, in order.
  void hold(bool held);

 private:
  void on_accepted(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback);
  void carry_out(SessionActions actions);
  // A request's actions, then the hook.
  void carry_out_request(SessionActions actions);
  // Reads and checks the asset on the loader's thread, then hands it on here.
  void load(session_action::LoadAsset load);
  // How much waits to be sent to `session` (nullopt: it is gone).
  [[nodiscard]] std::optional<std::size_t> queued_bytes(SessionId session) const;

  asio::io_context& io_;
  const config::ApiServer settings_;
  const std::uint32_t max_message_bytes_;
  spdlog::logger& log_;
  std::optional<JournalFile> journal_;
  SceneSessions sessions_;
  TcpListener listener_;
  std::function<std::uint64_t()> next_frame_;
  std::map<SessionId, std::shared_ptr<net::Connection>> connections_;
  std::map<SessionId, std::shared_ptr<http::WebSocketPeer>> websockets_;
  SessionId next_id_ = 1;
  const Uploads uploads_;
  AssetLoaded asset_loaded_;
  std::function<void()> request_handled_;
  bool held_ = false;
  std::vector<session::Event> events_held_;
  std::deque<std::function<void()>> requests_held_;  // from WebSockets
  // What a WebSocket's thread posts here finds the port gone once it is.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  // Reads assets, one at a time; joined first when the port goes.
  asio::thread_pool loader_{1};
};

}  // namespace optique::master
