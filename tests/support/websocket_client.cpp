#include "websocket_client.h"

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>

namespace optique::testing {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = boost::beast::websocket;

struct WebSocketClient::State {
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws{io};
  beast::flat_buffer inbox;
  bool reading = false;  // a read is pending (one left by a receive that timed out)
  bool read_done = false;
  beast::error_code read_error;

  // Runs the io until `done` or `timeout`; false on timeout.
  template <class Done>
  bool run_until(Done done, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!done()) {
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) return false;
      io.restart();
      io.run_one_for(deadline - now);
    }
    return true;
  }
};

WebSocketClient::WebSocketClient(int port, const std::string& target,
                                 const std::vector<std::pair<std::string, std::string>>& headers,
                                 const std::string& host, std::chrono::milliseconds timeout)
    : state_(std::make_unique<State>()) {
  State& s = *state_;
  bool done = false;
  beast::error_code error;
  s.ws.next_layer().async_connect(
      asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<unsigned short>(port)),
      [&](beast::error_code e) {
        error = e;
        done = true;
      });
  if (!s.run_until([&] { return done; }, timeout) || error) {
    error_ = "connect: " + (error ? error.message() : std::string("timed out"));
    closed_ = true;
    return;
  }
  s.ws.set_option(websocket::stream_base::decorator([headers](websocket::request_type& request) {
    for (const auto& [name, value] : headers) request.set(name, value);
  }));
  auto answer = std::make_shared<websocket::response_type>();
  done = false;
  s.ws.async_handshake(*answer, host, target, [&](beast::error_code e) {
    error = e;
    done = true;
  });
  if (!s.run_until([&] { return done; }, timeout)) {
    error_ = "upgrade: timed out";
    closed_ = true;
    return;
  }
  upgrade_status_ = static_cast<int>(answer->result_int());
  upgrade_body_ = answer->body();
  if (error) {
    error_ = "upgrade: " + error.message() + " (HTTP " + std::to_string(upgrade_status_) + ": " + upgrade_body_ + ")";
    closed_ = true;
  }
}

WebSocketClient::~WebSocketClient() = default;

bool WebSocketClient::open() const { return !closed_ && state_->ws.is_open(); }

bool WebSocketClient::write(const std::string& bytes, bool text, std::chrono::milliseconds timeout) {
  if (closed_) return false;
  State& s = *state_;
  s.ws.text(text);
  bool done = false;
  beast::error_code error;
  s.ws.async_write(asio::buffer(bytes), [&](beast::error_code e, std::size_t) {
    error = e;
    done = true;
  });
  if (!s.run_until([&] { return done; }, timeout)) {
    error_ = "send: timed out";
    beast::get_lowest_layer(s.ws).close();  // the pending write must not outlive `done`
    s.run_until([&] { return done; }, std::chrono::seconds(1));
    closed_ = true;
    return false;
  }
  if (error) error_ = "send: " + error.message();
  return !error;
}

bool WebSocketClient::send(const std::string& text, std::chrono::milliseconds timeout) {
  return write(text, true, timeout);
}

bool WebSocketClient::send_binary(const std::string& bytes, std::chrono::milliseconds timeout) {
  return write(bytes, false, timeout);
}

std::optional<std::string> WebSocketClient::receive(std::chrono::milliseconds timeout) {
  if (closed_) return std::nullopt;
  State& s = *state_;
  if (!s.reading) {
    s.reading = true;
    s.read_done = false;
    s.ws.async_read(s.inbox, [&s](beast::error_code e, std::size_t) {
      s.read_error = e;
      s.read_done = true;
    });
  }
  if (!s.run_until([&] { return s.read_done; }, timeout)) return std::nullopt;  // still pending
  s.reading = false;
  if (s.read_error) {
    closed_ = true;
    close_code_ = s.ws.reason().code;
    close_reason_ = std::string(s.ws.reason().reason.c_str());
    error_ = "receive: " + s.read_error.message();
    return std::nullopt;
  }
  std::string message = beast::buffers_to_string(s.inbox.data());
  s.inbox.clear();
  return message;
}

void WebSocketClient::close(std::chrono::milliseconds timeout) {
  if (closed_) return;
  State& s = *state_;
  bool done = false;
  s.ws.async_close(websocket::close_code::normal, [&](beast::error_code) { done = true; });
  s.run_until([&] { return done && (!s.reading || s.read_done); }, timeout);
  closed_ = true;
  beast::get_lowest_layer(s.ws).close();
  s.run_until([&] { return done && (!s.reading || s.read_done); }, std::chrono::seconds(1));
}

}  // namespace optique::testing
