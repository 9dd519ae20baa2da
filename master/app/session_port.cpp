#include "master/app/session_port.h"

#include "net/auth.h"
#include "util/overloaded.h"

namespace optique::master {
namespace {

// Before its hello an application has said nothing worth more.
constexpr std::uint32_t kMaxApplicationHelloBytes = 4096;
// The kernel's share of what waits for an application that stopped reading
// (Linux doubles it for its bookkeeping); the rest is bounded by SceneSessions.
constexpr int kSendBufferBytes = 128 * 1024;

}  // namespace

SessionPort::SessionPort(asio::io_context& io, const config::ApiServer& settings, LiveScene& live,
                         std::optional<JournalFile> journal, std::optional<net::Secret> secret,
                         std::uint32_t max_message_bytes, spdlog::logger& log)
    : settings_(settings),
      log_(log),
      journal_(std::move(journal)),
      sessions_(live, SceneSessionSettings{settings.max_sessions, max_message_bytes, std::move(secret),
                                           journal_.has_value()}),
      listener_(io, log) {}

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
}

void SessionPort::on_accepted(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback) {
  const SessionId id = next_id_++;
  boost::system::error_code ignored;  // the kernel's default is then the bound
  socket.set_option(asio::socket_base::send_buffer_size(kSendBufferBytes), ignored);
  auto connection = net::Connection::create(std::move(socket), kMaxApplicationHelloBytes);
  connections_[id] = connection;
  connection->start({
      [this, id](wire::Envelope& message, clock::Nanos) { carry_out(sessions_.message(id, message, next_frame_())); },
      [this, id](const std::string& reason) {
        connections_.erase(id);
        carry_out(sessions_.closed(id, reason));
      },
  });
  carry_out(sessions_.accepted(id, peer_text, loopback, net::random_nonce()));
}

void SessionPort::publish(const session::Event& event) {
  const clock::Nanos now = clock::monotonic_now();
  for (SessionAction& action : sessions_.publish(event)) {
    const SessionId to = std::get<session_action::Send>(action).session;
    carry_out({std::move(action)});
    if (const auto found = connections_.find(to); found != connections_.end()) {
      carry_out(sessions_.queued(to, found->second->queued_bytes(), now));
    }
  }
}

void SessionPort::carry_out(SessionActions actions) {
  for (SessionAction& action : actions) {
    std::visit(util::Overloaded{
                   [&](session_action::Send& a) {
                     if (auto found = connections_.find(a.session); found != connections_.end()) {
                       found->second->send(a.message);
                     }
                   },
                   [&](session_action::Close& a) {
                     const auto found = connections_.find(a.session);
                     if (found == connections_.end()) return;
                     if (a.after_sending) {
                       found->second->close_after_sending(a.reason);
                     } else {
                       found->second->close(a.reason);
                     }
                   },
                   [&](session_action::SetMaxPayload& a) {
                     if (auto found = connections_.find(a.session); found != connections_.end()) {
                       found->second->set_max_payload_bytes(a.bytes);
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
               },
               action);
  }
}

}  // namespace optique::master
