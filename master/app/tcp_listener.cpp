#include "master/app/tcp_listener.h"

#include <chrono>

#include "http/listen.h"

namespace optique::master {
namespace {

bool is_loopback(const asio::ip::address& address) {
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    return asio::ip::make_address_v4(asio::ip::v4_mapped, address.to_v6()).is_loopback();
  }
  return address.is_loopback();
}

}  // namespace

Result<std::uint16_t> TcpListener::listen(const std::string& address, std::uint16_t port) {
  return http::listen_on(acceptor_, address, port);
}

void TcpListener::start(Accepted accepted) {
  accepted_ = std::move(accepted);
  accept_next();
}

void TcpListener::close() {
  closed_ = true;
  retry_timer_.cancel();
  boost::system::error_code ignored;
  acceptor_.close(ignored);
}

void TcpListener::accept_next() {
  acceptor_.async_accept([this](const boost::system::error_code& error, asio::ip::tcp::socket socket) {
    if (error) {
      if (error == asio::error::operation_aborted || !acceptor_.is_open() || closed_) return;
      // Out of file descriptors and the like: try again shortly, and say so once
      // per failure streak rather than thousands of times a second.
      if (!failing_) log_.warn("accept failed: {}; retrying every 100 ms", error.message());
      failing_ = true;
      retry_timer_.expires_after(std::chrono::milliseconds(100));
      retry_timer_.async_wait([this](const boost::system::error_code& e) {
        if (!e && !closed_) accept_next();
      });
      return;
    }
    if (failing_) log_.info("accepting connections again");
    failing_ = false;
    boost::system::error_code ec;
    const asio::ip::tcp::endpoint peer = socket.remote_endpoint(ec);
    if (!ec) {  // else gone already
      accepted_(std::move(socket), peer.address().to_string() + ":" + std::to_string(peer.port()),
                is_loopback(peer.address()));
    }
    if (!closed_) accept_next();
  });
}

}  // namespace optique::master
