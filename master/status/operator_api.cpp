#include "master/status/operator_api.h"

#include <openssl/crypto.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <string_view>

#include "config/address.h"
#include "master/status/status_metrics.h"

namespace optique::master {
namespace {

bool starts_with_ignoring_case(std::string_view text, std::string_view prefix) {
  if (text.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(text[i])) != std::tolower(static_cast<unsigned char>(prefix[i])))
      return false;
  }
  return true;
}

bool all_digits(std::string_view text) {
  return std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// A Host that names this machine by number or as localhost, with a port or
// none (RFC 9110: host [":" port], an IPv6 address in brackets). Reads open on
// loopback answer only these: a web page whose name was rebound to 127.0.0.1
// (DNS rebinding) sends its own name, and learns nothing. Nothing may follow
// the name but the port's digits.
bool host_is_local(std::string_view host) {
  if (host.empty()) return true;  // HTTP/1.0
  std::string_view name = host;
  std::string_view port;
  if (host.front() == '[') {
    const auto end = host.find(']');
    if (end == std::string_view::npos) return false;
    name = host.substr(1, end - 1);
    const std::string_view rest = host.substr(end + 1);
    if (!rest.empty() && rest.front() != ':') return false;
    if (!rest.empty()) port = rest.substr(1);
    return all_digits(port) && config::is_ip_address(std::string(name));
  }
  if (const auto colon = host.rfind(':'); colon != std::string_view::npos) {
    name = host.substr(0, colon);
    port = host.substr(colon + 1);
  }
  return all_digits(port) && (name == "localhost" || config::is_ip_address(std::string(name)));
}

bool token_matches(std::string_view given, const std::string& token) {
  return given.size() == token.size() && CRYPTO_memcmp(given.data(), token.data(), token.size()) == 0;
}

// "Bearer <token>" with the right token, compared in constant time.
bool authorized(const http::Request& request, const std::string& token) {
  constexpr std::string_view kScheme = "Bearer ";
  if (!starts_with_ignoring_case(request.authorization, kScheme)) return false;
  std::string_view given = std::string_view(request.authorization).substr(kScheme.size());
  while (!given.empty() && given.front() == ' ') given.remove_prefix(1);
  while (!given.empty() && given.back() == ' ') given.remove_suffix(1);
  return token_matches(given, token);
}

// The value of `key` in a query ("a=1&b=2"), as sent (nullopt: not there).
std::optional<std::string_view> query_value(std::string_view query, std::string_view key) {
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    if (const auto equals = pair.find('='); equals != std::string_view::npos && pair.substr(0, equals) == key) {
      return pair.substr(equals + 1);
    }
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return std::nullopt;
}

http::Response unauthorized(std::string why) {
  http::Response response = http::text_response(401, std::move(why));
  response.headers.emplace_back("WWW-Authenticate", "Bearer realm=\"optique\"");
  return response;
}

http::Response serve(std::shared_ptr<const std::string> body, const char* content_type) {
  if (!body) return http::text_response(503, "the master has not published its status yet; try again shortly");
  http::Response response;
  response.content_type = content_type;
  response.body = std::move(body);
  return response;
}

http::Response method_not_allowed(const http::Request& request, const char* allow) {
  http::Response response =
      http::text_response(405, request.method_text + " " + request.path + ": not allowed (allowed: " + allow + ")");
  response.headers.emplace_back("Allow", allow);
  return response;
}

// A browser says which page opens a WebSocket; any page may try, so only this
// server's own (the operator's page) is let in. Scripts send no Origin.
bool same_origin(const http::Request& request) {
  return request.origin.empty() || request.origin == "http://" + request.host ||
         request.origin == "https://" + request.host;
}

constexpr std::string_view kDefaultApplication = "websocket";

// /api/session: a scene session's WebSocket.
Routed scene_session(const http::Request& request, const OperatorAccess& access) {
  if (request.method != http::Method::get) return {method_not_allowed(request, "GET"), std::nullopt};
  if (!access.scene_sessions) {
    return {http::text_response(404,
                                "/api/session: this master has no master.api, so no application may change "
                                "its scene"),
            std::nullopt};
  }
  if (!request.websocket_upgrade) {
    http::Response upgrade = http::text_response(
        426, "/api/session is the scene session's WebSocket: open ws://<this server>/api/session?application=NAME");
    upgrade.headers.emplace_back("Upgrade", "websocket");
    return {std::move(upgrade), std::nullopt};
  }
  if (!same_origin(request)) {
    return {http::text_response(403, "Origin '" + request.origin +
                                         "': from a browser, only this server's own page "
                                         "may open the scene session"),
            std::nullopt};
  }
  if (access.token) {
    const auto given = query_value(request.query, "token");
    if (!authorized(request, *access.token) && !(given && token_matches(*given, *access.token))) {
      return {unauthorized("the scene session needs the token, as a bearer token or ?token= "
                           "(optique-master --print-status-token)"),
              std::nullopt};
    }
  } else if (!request.peer_is_loopback || !host_is_local(request.host)) {
    return {http::text_response(403,
                                "the scene session is open to other machines only with the token, and this "
                                "master has none: it is derived from the shared secret (master.secret_file)"),
            std::nullopt};
  }
  http::Response upgrade;
  upgrade.status = 101;
  return {std::move(upgrade), std::nullopt,
          std::string(query_value(request.query, "application").value_or(kDefaultApplication))};
}

struct Control {
  std::string_view path;
  OperatorCommand command;
};
constexpr std::array<Control, 3> kControls{{{"/control/pause", OperatorCommand::pause},
                                            {"/control/resume", OperatorCommand::resume},
                                            {"/control/stop", OperatorCommand::stop}}};

}  // namespace

void StatusBoard::set(StatusTexts texts) {
  const std::lock_guard lock(mutex_);
  texts_ = std::move(texts);
}

StatusTexts StatusBoard::get() const {
  const std::lock_guard lock(mutex_);
  return texts_;
}

Routed route(const http::Request& request, const OperatorAccess& access, const StatusTexts& latest) {
  const bool read = request.method == http::Method::get || request.method == http::Method::head;
  for (const Control& control : kControls) {
    if (request.path != control.path) continue;
    if (request.method != http::Method::post) return {method_not_allowed(request, "POST"), std::nullopt};
    if (!access.token) {
      return {http::text_response(403,
                                  "controls need a bearer token, and this master has none: it is derived from "
                                  "the shared secret (master.secret_file)"),
              std::nullopt};
    }
    if (!authorized(request, *access.token)) {
      return {unauthorized("controls need the bearer token (optique-master --print-status-token)"), std::nullopt};
    }
    http::Response accepted;
    accepted.status = 202;
    accepted.content_type = "application/json";
    // Queued: the master carries it out on its own thread, and says in its log
    // (and the page's warnings) what came of it.
    accepted.body = std::make_shared<const std::string>("{\"command\":\"" + std::string(to_string(control.command)) +
                                                        "\",\"queued\":true}\n");
    return {std::move(accepted), control.command};
  }

  if (request.path == "/api/session") return scene_session(request, access);

  // The page holds no data: it asks for it with the token it is given.
  if (request.path == "/" || request.path == "/index.html") {
    if (!read) return {method_not_allowed(request, "GET, HEAD"), std::nullopt};
    http::Response page = serve(latest.page, "text/html; charset=utf-8");
    if (latest.page_policy) page.headers.emplace_back("Content-Security-Policy", *latest.page_policy);
    return {std::move(page), std::nullopt};
  }
  const bool data = request.path == "/status.json" || request.path == "/metrics" || request.path == "/events";
  if (!data) return {http::text_response(404, request.path + ": no such page (try /, /status.json or /metrics)"), {}};
  if (!read) return {method_not_allowed(request, "GET, HEAD"), std::nullopt};
  if (!access.reads_need_token && !host_is_local(request.host)) {
    return {http::text_response(403, "Host '" + request.host +
                                         "': this status server answers reads without a token only to this machine "
                                         "by its address or as localhost"),
            std::nullopt};
  }
  if (access.reads_need_token) {
    if (!access.token) return {http::text_response(403, "this status server needs a token and has none"), {}};
    if (!authorized(request, *access.token)) {
      return {unauthorized("this status server listens beyond loopback: it needs the bearer token "
                           "(optique-master --print-status-token)"),
              std::nullopt};
    }
  }
  if (request.path == "/status.json") return {serve(latest.json, "application/json"), std::nullopt};
  if (request.path == "/metrics") return {serve(latest.metrics, kMetricsContentType), std::nullopt};
  http::Response stream;
  stream.content_type = "text/event-stream";
  stream.event_stream = request.method == http::Method::get;  // HEAD: the header only
  return {std::move(stream), std::nullopt};
}

}  // namespace optique::master
