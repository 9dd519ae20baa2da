#pragma once
// A TCP port the master listens on (the nodes', the applications'): bound and
// listening, then every connection handed on with who it is from, and accept
// failures (out of file descriptors) retried every 100 ms, said once per streak.

#include <spdlog/logger.h>
#include <boost/asio.hpp>

#include <cstdint>
#include <functional>
#include <string>

#include "util/result.h"

namespace optique::master {

namespace asio = boost::asio;

class TcpListener {
 public:
  // `peer_text`: "address:port"; `loopback`: from this machine.
  using Accepted = std::function<void(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback)>;

  TcpListener(asio::io_context& io, spdlog::logger& log) : acceptor_(io), retry_timer_(io), log_(log) {}

  // Binds `address`:`port` (0: any free port) and listens; the port bound.
  [[nodiscard]] Result<std::uint16_t> listen(const std::string& address, std::uint16_t port);
  // Accepts until close().
  void start(Accepted accepted);
  void close();

 private:
  void accept_next();

  asio::ip::tcp::acceptor acceptor_;
  asio::steady_timer retry_timer_;
  spdlog::logger& log_;
  Accepted accepted_;
  bool failing_ = false;
  bool closed_ = false;
};

}  // namespace optique::master
