#pragma once
// A WebSocket client for tests, on its own io_context: every call waits at
// most the time it is given, so that a test that goes wrong fails rather than
// hangs. Reads only when asked: a client not asked to receive leaves pings
// unanswered and the server's messages in the kernel, as a stalled application.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace optique::testing {

class WebSocketClient {
 public:
  // Connects to 127.0.0.1:`port` and asks to upgrade `target`, with `headers`
  // added (an Origin, say) and `host` as the Host header.
  WebSocketClient(int port, const std::string& target,
                  const std::vector<std::pair<std::string, std::string>>& headers = {},
                  const std::string& host = "127.0.0.1", std::chrono::milliseconds timeout = std::chrono::seconds(5));
  ~WebSocketClient();
  WebSocketClient(const WebSocketClient&) = delete;
  WebSocketClient& operator=(const WebSocketClient&) = delete;

  [[nodiscard]] bool open() const;
  // Why it is not open (the upgrade refused, the connection closed).
  [[nodiscard]] const std::string& error() const { return error_; }
  // The HTTP status of the answer to the upgrade (101 when it was accepted).
  [[nodiscard]] int upgrade_status() const { return upgrade_status_; }
  [[nodiscard]] const std::string& upgrade_body() const { return upgrade_body_; }

  [[nodiscard]] bool send(const std::string& text, std::chrono::milliseconds timeout = std::chrono::seconds(5));
  [[nodiscard]] bool send_binary(const std::string& bytes, std::chrono::milliseconds timeout = std::chrono::seconds(5));
  // The next message; nullopt when none came within `timeout` or the server
  // closed (then closed() is true, with its code and reason).
  [[nodiscard]] std::optional<std::string> receive(std::chrono::milliseconds timeout = std::chrono::seconds(5));
  [[nodiscard]] bool closed() const { return closed_; }
  [[nodiscard]] int close_code() const { return close_code_; }
  [[nodiscard]] const std::string& close_reason() const { return close_reason_; }
  // Closes from this side (a normal close), waiting for the server's answer.
  void close(std::chrono::milliseconds timeout = std::chrono::seconds(2));

 private:
  struct State;
  bool write(const std::string& bytes, bool text, std::chrono::milliseconds timeout);
  std::unique_ptr<State> state_;
  std::string error_;
  int upgrade_status_ = 0;
  std::string upgrade_body_;
  bool closed_ = false;
  int close_code_ = 0;
  std::string close_reason_;
};

}  // namespace optique::testing
