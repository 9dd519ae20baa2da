#pragma once
// What the status server answers, decided without sockets: the operator's page,
// /status.json, /metrics, the page's event stream, and the controls
// (POST /control/pause, /control/resume, /control/stop). Who may ask:
// - reads are open when the server listens on loopback only; otherwise they
//   need the bearer token;
// - controls always need the token, and without a shared secret there is none.
// - the scene session's WebSocket (/api/session) needs the token where there
//   is one, given as a bearer token or in the query (token=, for a browser's
//   WebSocket, which cannot set headers); without one only this machine may
//   open it. From a browser, only the operator's own page may (its Origin).
// The token is derived from the installation's shared secret
// (net::status_token), so that a token seen on the network does not let a
// node in.

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "http/message.h"
#include "master/operator_command.h"

namespace optique::master {

// What is served: the page and its Content-Security-Policy (set once,
// master/status/page_policy.h), and the latest status (null until the first is
// published).
struct StatusTexts {
  std::shared_ptr<const std::string> page;
  std::shared_ptr<const std::string> page_policy;
  std::shared_ptr<const std::string> json;
  std::shared_ptr<const std::string> metrics;
};

// Handed from the frame loop's thread to the server's.
class StatusBoard {
 public:
  void set(StatusTexts texts);
  [[nodiscard]] StatusTexts get() const;

 private:
  mutable std::mutex mutex_;
  StatusTexts texts_;
};

struct OperatorAccess {
  bool reads_need_token = false;     // the server listens beyond loopback
  std::optional<std::string> token;  // none without a shared secret
  bool scene_sessions = false;       // master.api: applications may open /api/session
};

struct Routed {
  Routed(http::Response answer, std::optional<OperatorCommand> carry_out = std::nullopt,
         std::optional<std::string> open_session = std::nullopt)
      : response(std::move(answer)), command(carry_out), scene_session(std::move(open_session)) {}

  http::Response response;
  std::optional<OperatorCommand> command;  // for the master to carry out
  // The WebSocket of a scene session, for the application so named: the
  // master makes its endpoint (the response is then status 101).
  std::optional<std::string> scene_session;
};

[[nodiscard]] Routed route(const http::Request& request, const OperatorAccess& access, const StatusTexts& latest);

}  // namespace optique::master
