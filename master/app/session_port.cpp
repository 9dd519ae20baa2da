#include "master/app/session_port.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "master/session/session_json.h"
#include "net/auth.h"
#include "scene_load/installation_scene.h"
#include "util/background_thread.h"
#include "util/overloaded.h"
#include "util/sha256.h"

namespace optique::master {
namespace {

// An uploaded binary glTF kept in `folder` by its SHA-256 (written whole,
// then renamed into place): the path.
Result<std::string> keep_upload(const std::string& folder, const std::string& glb) {
  const std::filesystem::path path = std::filesystem::path(folder) / (util::sha256_hex(glb) + ".glb");
  if (std::filesystem::exists(path)) return path.string();
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) return Error{"cannot make " + folder + ": " + error.message()};
  const std::filesystem::path partial = path.string() + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    out.write(glb.data(), static_cast<std::streamsize>(glb.size()));
    if (!out.flush()) return Error{"cannot write " + partial.string()};
  }
  std::filesystem::rename(partial, path, error);
  if (error) return Error{"cannot write " + path.string() + ": " + error.message()};
  return path.string();
}

// What the loader's thread makes of a LoadAsset: the asset, or why not.
struct AssetRead {
  std::shared_ptr<const scene::LoadedScene> asset;
  std::string error;
};

AssetRead read_asset(const session_action::LoadAsset& load, const std::string& folder, const std::string& uploads) {
  std::string path = load.path;
  if (!load.path.empty()) {
    // A link inside the folder must not lead out of it.
    std::error_code error;
    const std::filesystem::path inside = std::filesystem::weakly_canonical(folder, error);
    const std::filesystem::path file = std::filesystem::weakly_canonical(load.path, error);
    const auto [end, ignored] = std::mismatch(inside.begin(), inside.end(), file.begin(), file.end());
    if (error || end != inside.end()) return {nullptr, "is not inside master.api.assets (" + folder + ")"};
  } else {
    auto kept = keep_upload(uploads, load.glb);
    if (!kept) return {nullptr, kept.error()};
    path = kept.value();
  }
  // The master draws nothing: the images are read by the nodes.
  auto loaded = config::load_asset(load.asset, path, {});
  if (!loaded) return {nullptr, loaded.error()};
  return {std::make_shared<const scene::LoadedScene>(std::move(loaded).value()), ""};
}

// Before its hello an application has said nothing worth more.
constexpr std::uint32_t kMaxApplicationHelloBytes = 4096;
// The kernel's share of what waits for an application that stopped reading
// (Linux doubles it for its bookkeeping); the rest is bounded by SceneSessions.
constexpr int kSendBufferBytes = 128 * 1024;
// What may wait for one WebSocket at once, a scene read of many instances
// included. One that stops reading is closed long before, by SceneSessions's
// rule (SceneSessionSettings::max_queued_bytes for stalled_for).
constexpr std::size_t kMaxWebSocketQueuedBytes = 64u << 20;

}  // namespace

SessionPort::SessionPort(asio::io_context& io, const config::ApiServer& settings, LiveScene& live,
                         std::optional<JournalFile> journal, std::optional<net::Secret> secret,
                         std::uint32_t max_message_bytes, Uploads uploads, spdlog::logger& log)
    : io_(io),
      settings_(settings),
      max_message_bytes_(max_message_bytes),
      log_(log),
      journal_(std::move(journal)),
      sessions_(live, SceneSessionSettings{.max_sessions = settings.max_sessions,
                                           .max_message_bytes = max_message_bytes,
                                           .secret = std::move(secret),
                                           .journal = journal_.has_value(),
                                           .assets_folder = settings.assets}),
      listener_(io, log),
      uploads_(std::move(uploads)) {
  asio::post(loader_, [&log] {
    if (const std::string why = util::lower_this_threads_priority(); !why.empty()) {
      log.debug("the asset loader's thread keeps its priority: {}", why);
    }
  });
}

SessionPort::~SessionPort() {
  loader_.join();  // no load writes there any more
  if (uploads_.for_this_run_only) {
    std::error_code ignored;
    std::filesystem::remove_all(uploads_.folder, ignored);
  }
}

Result<std::uint16_t> SessionPort::start(std::function<std::uint64_t()> next_frame) {
  next_frame_ = std::move(next_frame);
  auto bound = listener_.listen(settings_.listen, settings_.port);
  if (!bound) return Error{"master.api: " + bound.error()};
  listener_.start([this](asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback) {
    on_accepted(std::move(socket), peer_text, loopback);
  });
  return bound;
}

void SessionPort::close(const std::string& reason) {
  listener_.close();
  wire::Envelope goodbye;
  goodbye.mutable_goodbye()->set_reason(reason);
  // Closing may call back into connections_: walk a copy.
  const auto open = connections_;
  for (const auto& [id, connection] : open) {
    if (!connection->is_open()) continue;
    connection->send(goodbye);
    connection->close_after_sending(reason);
  }
  for (const auto& [id, peer] : websockets_) {
    peer->send(to_application_json(goodbye));
    peer->close(reason);
  }
}

std::shared_ptr<http::WebSocketEndpoint> SessionPort::websocket(const std::string& application,
                                                                const std::string& peer_text) {
  auto endpoint = std::make_shared<http::WebSocketEndpoint>();
  endpoint->max_message_bytes = max_message_bytes_;
  endpoint->max_queued_bytes = kMaxWebSocketQueuedBytes;
  // Its session id, given on this port's thread (0 until then), read only
  // there. The callbacks run on the WebSocket's thread: they touch nothing of
  // the port but its io_context, and what they post checks that it still is.
  auto id = std::make_shared<SessionId>(0);
  const std::weak_ptr<bool> alive = alive_;
  endpoint->opened = [this, &io = io_, alive, id, application, peer_text](std::shared_ptr<http::WebSocketPeer> peer) {
    asio::post(io, [this, alive, id, application, peer_text, peer = std::move(peer)] {
      if (alive.expired()) return;
      *id = next_id_++;
      websockets_[*id] = peer;
      carry_out(sessions_.opened(*id, peer_text + " (WebSocket)", application));
    });
  };
  // Read on the WebSocket's thread: the port's thread gets a typed request.
  endpoint->received = [this, &io = io_, alive, id](std::string text) {
    asio::post(io, [this, alive, id, request = request_from_json(text)] {
      if (alive.expired() || *id == 0) return;
      auto handle = [this, id, request] {
        if (!websockets_.contains(*id)) return;  // it closed while held
        carry_out_request(request ? sessions_.request(*id, request.value(), next_frame_())
                                  : sessions_.unreadable(*id, request.error()));
      };
      if (held_) {
        requests_held_.push_back(std::move(handle));
      } else {
        handle();
      }
    });
  };
  endpoint->closed = [this, &io = io_, alive, id](const std::string& reason) {
    asio::post(io, [this, alive, id, reason] {
      if (alive.expired() || *id == 0) return;
      websockets_.erase(*id);
      carry_out(sessions_.closed(*id, reason));
    });
  };
  return endpoint;
}

void SessionPort::on_accepted(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback) {
  const SessionId id = next_id_++;
  boost::system::error_code ignored;  // the kernel's default is then the bound
  socket.set_option(asio::socket_base::send_buffer_size(kSendBufferBytes), ignored);
  auto connection = net::Connection::create(std::move(socket), kMaxApplicationHelloBytes);
  connections_[id] = connection;
  connection->hold_reading(held_);
  connection->start({
      [this, id](wire::Envelope& message, clock::Nanos) {
        carry_out_request(sessions_.message(id, message, next_frame_()));
      },
      [this, id](const std::string& reason) {
        connections_.erase(id);
        carry_out(sessions_.closed(id, reason));
      },
      [this, id](std::uint32_t bytes, std::uint32_t max_bytes) {
        carry_out(sessions_.unreadable(
            id, std::to_string(bytes) + " bytes, more than the " + std::to_string(max_bytes) +
                    " this master takes (master.max_message_bytes): send less at once (a large model: put its file "
                    "in master.api.assets and load it by path)"));
      },
  });
  carry_out(sessions_.accepted(id, peer_text, loopback, net::random_nonce()));
}

void SessionPort::hold(bool held) {
  if (held == held_) return;
  held_ = held;
  for (const auto& [id, connection] : connections_) connection->hold_reading(held);
  if (held) return;
  for (const session::Event& event : std::exchange(events_held_, {})) publish(event);
  while (!held_ && !requests_held_.empty()) {
    auto handle = std::move(requests_held_.front());
    requests_held_.pop_front();
    handle();
  }
}

void SessionPort::publish(const session::Event& event) {
  if (held_) {
    events_held_.push_back(event);
    return;
  }
  const clock::Nanos now = clock::monotonic_now();
  for (SessionAction& action : sessions_.publish(event)) {
    const SessionId to = std::get<session_action::Send>(action).session;
    carry_out({std::move(action)});
    if (const auto bytes = queued_bytes(to)) carry_out(sessions_.queued(to, *bytes, now));
  }
}

std::optional<std::size_t> SessionPort::queued_bytes(SessionId session) const {
  if (const auto found = connections_.find(session); found != connections_.end()) {
    return found->second->queued_bytes();
  }
  if (const auto found = websockets_.find(session); found != websockets_.end()) {
    return found->second->queued_bytes();
  }
  return std::nullopt;
}

void SessionPort::load(session_action::LoadAsset load) {
  const std::weak_ptr<bool> alive = alive_;
  asio::post(loader_,
             [this, &io = io_, alive, folder = settings_.assets, uploads = uploads_.folder, load = std::move(load)] {
               AssetRead read = read_asset(load, folder, uploads);
               asio::post(io, [this, alive, id = load.asset, from_file = !load.path.empty(), read = std::move(read)] {
                 if (alive.expired()) return;
                 if (!read.asset) {
                   carry_out(sessions_.asset_failed(id, from_file ? "load_asset.path" : "load_asset.glb", read.error));
                   return;
                 }
                 for (const std::string& warning : read.asset->warnings) log_.warn("asset '{}': {}", id, warning);
                 for (const std::string& note : read.asset->notes) log_.info("asset '{}': {}", id, note);
                 if (asset_loaded_) asset_loaded_(id, read.asset);
               });
             });
}

void SessionPort::asset_usable(const AssetUsable& usable) {
  carry_out(sessions_.asset_loaded(usable.asset, usable.frame, usable.animated, usable.path, usable.sha256));
}

void SessionPort::asset_unusable(const std::string& id, const std::string& reason) {
  carry_out(sessions_.asset_failed(id, "load_asset", reason));
}

void SessionPort::carry_out_request(SessionActions actions) {
  carry_out(std::move(actions));
  if (request_handled_) request_handled_();
}

void SessionPort::carry_out(SessionActions actions) {
  for (SessionAction& action : actions) {
    std::visit(util::Overloaded{
                   [&](session_action::Send& a) {
                     if (auto found = connections_.find(a.session); found != connections_.end()) {
                       found->second->send(a.message);
                     } else if (auto web = websockets_.find(a.session); web != websockets_.end()) {
                       if (std::string json = to_application_json(a.message); !json.empty()) {
                         web->second->send(std::move(json));
                       }
                     }
                   },
                   [&](session_action::Close& a) {
                     if (auto web = websockets_.find(a.session); web != websockets_.end()) {
                       // A refusal goes after what was sent; a reader that stopped, now.
                       if (a.after_sending) {
                         web->second->close(a.reason);
                       } else {
                         web->second->reset(a.reason);
                       }
                       return;
                     }
                     const auto found = connections_.find(a.session);
                     if (found == connections_.end()) return;
                     if (a.after_sending) {
                       found->second->close_after_sending(a.reason);
                     } else {
                       found->second->close(a.reason);
                     }
                   },
                   [&](session_action::SetMaxPayload& a) {
                     // Past its hello: a message over the size is refused, and the session goes on.
                     if (auto found = connections_.find(a.session); found != connections_.end()) {
                       found->second->set_max_payload_bytes(a.bytes);
                       found->second->skip_oversized();
                     }
                   },
                   [&](session_action::Protect& a) {
                     if (auto found = connections_.find(a.session); found != connections_.end()) {
                       found->second->protect(a.keys.to_node, a.keys.to_master, false);
                     }
                   },
                   [&](session_action::Journal& a) {
                     if (!journal_) return;
                     if (auto wrote = journal_->append(a.entry); !wrote) {
                       // The show goes on; what follows is not recorded, and the operator is told.
                       log_.error("the journal: {}; transactions from now on are not recorded", wrote.error());
                       journal_.reset();
                     }
                   },
                   [&](session_action::Log& a) { log_.log(a.level, "{}", a.text); },
                   [&](session_action::LoadAsset& a) { load(std::move(a)); },
               },
               action);
  }
}

}  // namespace optique::master
