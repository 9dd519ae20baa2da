#pragma once
// The master's status server, as its shell runs it: http::Server on a thread of
// its own (clients never delay the frame loop), answering by route()
// (master/status/operator_api.h) from what the frame loop last published. Commands
// from the page are handed to `on_command` on the server's thread; the master
// posts them to its own.

#include <spdlog/logger.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <boost/asio/io_context.hpp>

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "config/installation.h"
#include "http/server.h"
#include "master/live_status.h"
#include "master/status/operator_api.h"
#include "util/result.h"

namespace optique::master {

// The last warnings the log said, for the page: a sink the CLI adds to the
// master's logger.
inline constexpr std::size_t kWarningsShown = 20;
using WarningSink = spdlog::sinks::ringbuffer_sink_mt;
[[nodiscard]] std::shared_ptr<WarningSink> make_warning_sink();
[[nodiscard]] std::vector<LiveWarning> last_warnings(WarningSink& sink);

class StatusService {
 public:
  using CommandSink = std::function<void(OperatorCommand command, const std::string& from)>;
  // What becomes of a scene session's WebSocket that route() let in
  // (SessionPort::websocket), asked on the server's thread.
  using SessionOpener =
      std::function<std::shared_ptr<http::WebSocketEndpoint>(const std::string& application, const std::string& peer)>;

  StatusService(const config::StatusServer& settings, OperatorAccess access, CommandSink on_command,
                SessionOpener open_session, spdlog::logger& log);
  ~StatusService();  // stops the server and joins its thread
  StatusService(const StatusService&) = delete;
  StatusService& operator=(const StatusService&) = delete;

  // Listens and starts the thread; the port bound.
  [[nodiscard]] Result<std::uint16_t> start();
  // On the master's thread: serves `status` from now on, and sends it to every
  // page's stream.
  void publish(const LiveStatus& status);
  [[nodiscard]] LiveClients clients() const;

 private:
  config::StatusServer settings_;
  OperatorAccess access_;
  CommandSink on_command_;
  SessionOpener open_session_;
  StatusBoard board_;
  boost::asio::io_context io_;
  http::Server server_;
  std::thread thread_;
};

}  // namespace optique::master
