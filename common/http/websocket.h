#pragma once
// A WebSocket (RFC 6455) that a handler accepts on http::Server: text messages
// both ways, with the server's bounds. The handler says what becomes of it (an
// Endpoint in its Response); the server upgrades the connection, reads every
// message up to a size, writes what the endpoint sends in order, and closes a
// peer that lets more than a bound wait for it rather than buffer without end.
// A peer that goes silent is pinged, and closed when it does not answer.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

namespace optique::http {

// The accepted WebSocket, as the endpoint's owner holds it. Any thread may
// call it; what it does happens on the server's thread, in order.
class WebSocketPeer {
 public:
  virtual ~WebSocketPeer() = default;
  // One text message (valid UTF-8). A closed peer drops it.
  virtual void send(std::string text) = 0;
  // Closes once what was sent before has gone, with `reason` in the close
  // frame (cut to what a close frame holds).
  virtual void close(std::string reason) = 0;
  // Closes now, dropping what waits (a client that stopped reading).
  virtual void reset(std::string reason) = 0;
  // What waits to be written to it now, not counting the kernel's buffer.
  [[nodiscard]] virtual std::size_t queued_bytes() const = 0;
};

// What becomes of a WebSocket: called on the server's thread, `opened` first,
// then `received` for each text message, then `closed` once, whoever closed it
// (the owner's close() too). A binary message closes it (close code 1003).
struct WebSocketEndpoint {
  // A larger message closes the WebSocket (close code 1009).
  std::size_t max_message_bytes = 64 * 1024;
  // More than this waiting to be written closes it (close code 1008): a
  // client that stopped reading.
  std::size_t max_queued_bytes = 4u << 20;
  std::function<void(std::shared_ptr<WebSocketPeer> peer)> opened;
  std::function<void(std::string text)> received;
  std::function<void(const std::string& reason)> closed;
};

}  // namespace optique::http
