#pragma once
// An HTTP request and its answer as the handler behind http::Server sees them:
// parsed and bounded by the server, with no socket in sight, so what to answer
// (paths, methods, tokens) is decided and tested without a network.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "http/websocket.h"

namespace optique::http {

enum class Method { get, head, post, other };

struct Request {
  Method method = Method::get;
  std::string method_text;    // as sent, for messages
  std::string path;           // the target up to '?'
  std::string query;          // after '?', as sent
  std::string authorization;  // the Authorization header; empty: none
  std::string host;           // the Host header; empty: none
  std::string origin;         // the Origin header (a browser's page); empty: none
  std::string peer;           // "address:port"
  bool peer_is_loopback = false;
  bool websocket_upgrade = false;  // asks to become a WebSocket (RFC 6455)
};

struct Response {
  unsigned status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  // Shared: one status text goes to every client that asks until the next.
  std::shared_ptr<const std::string> body = std::make_shared<const std::string>();
  std::vector<std::pair<std::string, std::string>> headers;
  // The connection becomes a stream of server-sent events (text/event-stream):
  // every Server::publish() from now on, until either side closes it.
  bool event_stream = false;
  // To a WebSocket upgrade, with status 101: the connection becomes this
  // WebSocket (http/websocket.h). Ignored on any other request.
  std::shared_ptr<WebSocketEndpoint> websocket;
};

// A plain-text answer; the text ends with a newline.
[[nodiscard]] Response text_response(unsigned status, std::string text);

}  // namespace optique::http
