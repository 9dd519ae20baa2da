#pragma once
// A small HTTP/1.1 server (Boost.Beast) for the operator's page and metrics: it
// reads and bounds requests, asks a Handler what to answer, and writes the
// answer; it decides nothing else. Answers that are event streams stay open and
// get every publish(). Limits like the node port's: a connection limit, one per
// address and slots kept for this machine (http/connection_budget.h; the next
// one is answered 503 and closed), a whole request within a time (slow clients
// are closed), header and body sizes (431/413, then closed), and event streams
// that fall behind are closed rather than buffered without end, in the kernel
// too. Every answer says it is not to be framed or sniffed. A handler may
// accept a WebSocket upgrade (http/websocket.h), bounded likewise.
//
// Runs on the io_context it is given, meant to be its own thread's, so that
// clients never delay the frame loop; publish() and stop() may be called from
// any thread.

#include <spdlog/logger.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "http/connection_budget.h"
#include "http/message.h"
#include "util/result.h"

namespace optique::http {

namespace asio = boost::asio;

struct ServerLimits {
  std::size_t max_connections = 256;
  // From one address not on this machine (an IPv6 /64 counts as one).
  std::size_t max_per_address = 16;
  // Of max_connections (at most half), only for peers on this machine.
  std::size_t loopback_reserved = 8;
  // The whole header: request line, fields and the blank line that ends them.
  std::uint32_t max_header_bytes = 8 * 1024;
  std::uint32_t max_body_bytes = 1024;
  // From a connection's start, or the end of its last answer, to a whole request.
  std::chrono::milliseconds request_timeout{5000};
  // To write one answer or one event.
  std::chrono::milliseconds write_timeout{5000};
  // Events queued for one stream beyond these close it.
  std::size_t max_queued_events = 32;
  // An event stream's socket send buffer (SO_SNDBUF, which Linux doubles): what
  // the kernel holds for a client that does not read, where it would otherwise
  // grow to 4 MiB. A stream closed for falling behind is reset, so that the
  // kernel drops what it still held for it.
  int stream_send_buffer = 32 * 1024;
  // A WebSocket that hears nothing from its client this long is closed; it is
  // pinged halfway, so a client that is there but quiet answers and stays.
  std::chrono::milliseconds websocket_idle{30000};
};

// What the server did, for the status and the tests; read from any thread.
struct ServerCounts {
  std::uint64_t accepted = 0;
  std::uint64_t requests = 0;
  std::uint64_t refused_busy = 0;     // over max_connections (or the part of it not kept for loopback)
  std::uint64_t refused_address = 0;  // over max_per_address
  std::uint64_t timed_out = 0;        // a request or a write took too long
  std::uint64_t too_large = 0;        // header or body over the limit
  std::uint64_t bad_requests = 0;     // not HTTP
  std::uint64_t streams_behind = 0;   // event streams closed for falling behind
  std::uint64_t open = 0;             // connections open now
  std::uint64_t streams = 0;          // event streams open now
  std::uint64_t websockets = 0;       // WebSockets open now
};

class Server {
 public:
  using Handler = std::function<Response(const Request&)>;

  Server(asio::io_context& io, ServerLimits limits, Handler handler, spdlog::logger& log);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts accepting; the port bound (port 0: an ephemeral one).
  [[nodiscard]] Result<std::uint16_t> listen(const std::string& address, std::uint16_t port);
  // One event, `data` a line of text (no newline), to every event stream.
  void publish(std::shared_ptr<const std::string> data);
  // Stops accepting and closes every connection.
  void stop();
  [[nodiscard]] ServerCounts counts() const;

  class Session;  // one connection
  class Peer;     // a Session's WebSocket, as its endpoint's owner holds it

 private:
  friend class Session;
  void accept_next();
  void on_closed(std::uint64_t id);

  asio::io_context& io_;
  ServerLimits limits_;
  Handler handler_;
  spdlog::logger& log_;
  asio::ip::tcp::acceptor acceptor_;
  asio::steady_timer accept_retry_;
  // On the io thread only. A session lives while an operation of its own is
  // pending; an event stream waits for events, so the server holds it.
  struct Open {
    std::weak_ptr<Session> session;
    asio::ip::address peer;
  };
  std::map<std::uint64_t, Open> sessions_;
  ConnectionBudget budget_;
  std::map<std::uint64_t, std::shared_ptr<Session>> streams_;
  std::uint64_t next_id_ = 1;
  bool stopped_ = false;
  bool accept_failing_ = false;  // said once per streak
  struct Counters {
    std::atomic<std::uint64_t> accepted{0}, requests{0}, refused_busy{0}, refused_address{0}, timed_out{0},
        too_large{0}, bad_requests{0}, streams_behind{0}, open{0}, streams{0}, websockets{0};
  };
  std::shared_ptr<Counters> counters_ = std::make_shared<Counters>();
};

}  // namespace optique::http
