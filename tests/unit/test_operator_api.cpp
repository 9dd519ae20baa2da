// The status server's answers, decided without a network: which path gives
// what, which method is allowed, and who may read or control; and the page's
// Content-Security-Policy (master/status/page_policy.h).

#include <gtest/gtest.h>

#include <algorithm>

#include "master/status/operator_api.h"
#include "master/status/page_policy.h"
#include "master/status/status_metrics.h"

namespace optique::master {
namespace {

const std::string kToken = std::string(64, 'a');

http::Request request(http::Method method, const std::string& path, const std::string& authorization = "") {
  http::Request r;
  r.method = method;
  r.method_text = method == http::Method::post ? "POST" : method == http::Method::get ? "GET" : "HEAD";
  r.path = path;
  r.authorization = authorization;
  r.peer = "127.0.0.1:50000";
  return r;
}

StatusTexts published() {
  return {std::make_shared<const std::string>("<html>page</html>"),
          std::make_shared<const std::string>("default-src 'none'"), std::make_shared<const std::string>("{\"a\":1}"),
          std::make_shared<const std::string>("optique_up 1\n")};
}

const OperatorAccess kLoopback{false, kToken};
const OperatorAccess kBeyondLoopback{true, kToken};
const OperatorAccess kNoSecret{false, std::nullopt};

TEST(OperatorApi, OnLoopbackReadsAreOpen) {
  const StatusTexts texts = published();
  Routed r = route(request(http::Method::get, "/"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 200u);
  EXPECT_EQ(r.response.content_type, "text/html; charset=utf-8");
  EXPECT_EQ(*r.response.body, "<html>page</html>");
  r = route(request(http::Method::get, "/status.json"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 200u);
  EXPECT_EQ(r.response.content_type, "application/json");
  EXPECT_EQ(r.response.body, texts.json) << "the published text itself, not a copy";
  r = route(request(http::Method::get, "/metrics"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 200u);
  EXPECT_EQ(r.response.content_type, kMetricsContentType);
  r = route(request(http::Method::get, "/events"), kLoopback, texts);
  EXPECT_TRUE(r.response.event_stream);
  EXPECT_FALSE(r.command);
  r = route(request(http::Method::head, "/status.json"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 200u) << "HEAD as GET (the server sends no body)";
  r = route(request(http::Method::head, "/events"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 200u);
  EXPECT_FALSE(r.response.event_stream) << "HEAD gets the header, not a stream";
  EXPECT_EQ(r.response.content_type, "text/event-stream");
}

// Reads open on loopback answer this machine by its address or as localhost
// only: a page whose name was rebound to 127.0.0.1 sends its own name.
TEST(OperatorApi, OpenReadsRefuseAForeignHost) {
  const StatusTexts texts = published();
  for (const char* host : {"127.0.0.1:7480", "localhost:7480", "[::1]:7480", "localhost", ""}) {
    http::Request r = request(http::Method::get, "/status.json");
    r.host = host;
    EXPECT_EQ(route(r, kLoopback, texts).response.status, 200u) << host;
  }
  http::Request rebound = request(http::Method::get, "/metrics");
  rebound.host = "attacker.example:7480";
  const Routed r = route(rebound, kLoopback, texts);
  EXPECT_EQ(r.response.status, 403u);
  EXPECT_NE(r.response.body->find("Host 'attacker.example:7480'"), std::string::npos);
  rebound.authorization = "Bearer " + kToken;
  EXPECT_EQ(route(rebound, kBeyondLoopback, texts).response.status, 200u) << "with the token, any name";
  // Names that begin or end like this machine's are not it.
  for (const char* host :
       {"localhost.attacker.example", "localhost.attacker.example:7480", "127.0.0.1.attacker.example",
        "attacker.localhost.example", "localhostx", "[::1].attacker.example", "[::1]x:7480",
        "attacker.example:localhost", "localhost:7480@attacker.example"}) {
    http::Request foreign = request(http::Method::get, "/status.json");
    foreign.host = host;
    EXPECT_EQ(route(foreign, kLoopback, texts).response.status, 403u) << host;
  }
}

TEST(OperatorApi, BeyondLoopbackDataNeedsTheToken) {
  const StatusTexts texts = published();
  for (const char* path : {"/status.json", "/metrics", "/events"}) {
    Routed r = route(request(http::Method::get, path), kBeyondLoopback, texts);
    EXPECT_EQ(r.response.status, 401u) << path;
    ASSERT_FALSE(r.response.headers.empty());
    EXPECT_EQ(r.response.headers.front().first, "WWW-Authenticate");
    EXPECT_NE(r.response.body->find("--print-status-token"), std::string::npos);
    EXPECT_EQ(route(request(http::Method::get, path, "Bearer " + std::string(64, 'b')), kBeyondLoopback, texts)
                  .response.status,
              401u)
        << path << ": a wrong token";
    EXPECT_EQ(
        route(request(http::Method::get, path, "Bearer " + kToken.substr(1)), kBeyondLoopback, texts).response.status,
        401u)
        << path << ": a token one character short";
    EXPECT_EQ(route(request(http::Method::get, path, "Basic " + kToken), kBeyondLoopback, texts).response.status, 401u)
        << path << ": another scheme";
    for (const std::string& longer : {kToken + "a", kToken + "0", kToken + " " + kToken, kToken + "\t", kToken + ",x",
                                      kToken + std::string(1, '\0')}) {
      EXPECT_EQ(route(request(http::Method::get, path, "Bearer " + longer), kBeyondLoopback, texts).response.status,
                401u)
          << path << ": the token with more after it (" << longer.size() << " characters)";
    }
    r = route(request(http::Method::get, path, "bearer  " + kToken + " "), kBeyondLoopback, texts);
    EXPECT_TRUE(r.response.status == 200u || r.response.event_stream) << path << ": the scheme in any case";
  }
  // The page holds no data: it is served to anyone, and asks for the token.
  EXPECT_EQ(route(request(http::Method::get, "/"), kBeyondLoopback, texts).response.status, 200u);
}

TEST(OperatorApi, ControlsRefuseATokenWithMoreAfterIt) {
  const StatusTexts texts = published();
  const Routed r = route(request(http::Method::post, "/control/stop", "Bearer " + kToken + "x"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 401u);
  EXPECT_FALSE(r.command);
}

TEST(OperatorApi, ThePageIsServedWithItsSecurityPolicy) {
  const StatusTexts texts = published();
  const Routed r = route(request(http::Method::get, "/"), kBeyondLoopback, texts);
  ASSERT_EQ(r.response.status, 200u);
  const auto policy = std::find_if(r.response.headers.begin(), r.response.headers.end(),
                                   [](const auto& header) { return header.first == "Content-Security-Policy"; });
  ASSERT_NE(policy, r.response.headers.end());
  EXPECT_EQ(policy->second, *texts.page_policy);
}

// The hashes, worked out apart (python3: base64 of hashlib.sha256(text)), of
// exactly what stands between the tags.
TEST(PagePolicy, AllowsThePagesOwnScriptAndStyleByHashAndNothingElse) {
  const std::string policy =
      page_security_policy("<!doctype html><style> p { color: red; } </style><p>x</p><script>alert(1)</script>");
  EXPECT_NE(policy.find("script-src 'sha256-bhHHL3z2vDgxUt0W3dWQOrprscmda2Y5pLsLg4GF+pI=';"), std::string::npos)
      << policy;
  EXPECT_NE(policy.find("style-src 'sha256-u/blH8m0r/Q1cgkpEic0SpNGAC4pqGOrjgBEon2/AYo=';"), std::string::npos)
      << policy;
  EXPECT_EQ(policy.rfind("default-src 'none';", 0), 0u) << policy;
  EXPECT_NE(policy.find("connect-src 'self'"), std::string::npos) << policy;
  EXPECT_NE(policy.find("frame-ancestors 'none'"), std::string::npos) << policy;
  EXPECT_EQ(policy.find("unsafe"), std::string::npos) << policy;
  const std::string none = page_security_policy("<p>no script</p>");
  EXPECT_NE(none.find("script-src 'none';"), std::string::npos) << none;
  EXPECT_NE(none.find("style-src 'none';"), std::string::npos) << none;
  const std::string two = page_security_policy("<script>a</script><script type=\"module\">b</script>");
  std::size_t hashes = 0;
  for (std::size_t at = two.find("'sha256-"); at != std::string::npos; at = two.find("'sha256-", at + 1)) ++hashes;
  EXPECT_EQ(hashes, 2u) << "each script, attributes or not: " << two;
}

TEST(OperatorApi, ControlsAlwaysNeedTheToken) {
  const StatusTexts texts = published();
  Routed r = route(request(http::Method::post, "/control/pause"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 401u) << "even on loopback";
  EXPECT_FALSE(r.command);
  r = route(request(http::Method::post, "/control/stop", "Bearer wrong"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 401u);
  EXPECT_FALSE(r.command);
  r = route(request(http::Method::post, "/control/pause", "Bearer " + kToken), kLoopback, texts);
  EXPECT_EQ(r.response.status, 202u);
  EXPECT_EQ(*r.response.body, "{\"command\":\"pause\",\"queued\":true}\n");
  EXPECT_EQ(r.command, OperatorCommand::pause);
  EXPECT_EQ(route(request(http::Method::post, "/control/resume", "Bearer " + kToken), kLoopback, texts).command,
            OperatorCommand::resume);
  EXPECT_EQ(route(request(http::Method::post, "/control/stop", "Bearer " + kToken), kLoopback, texts).command,
            OperatorCommand::stop);
  // Without a shared secret there is no token: controls are off, and say why.
  r = route(request(http::Method::post, "/control/stop", "Bearer " + kToken), kNoSecret, texts);
  EXPECT_EQ(r.response.status, 403u);
  EXPECT_NE(r.response.body->find("master.secret_file"), std::string::npos);
  EXPECT_FALSE(r.command);
}

TEST(OperatorApi, WrongMethodsAndPathsAreRefusedByName) {
  const StatusTexts texts = published();
  Routed r = route(request(http::Method::get, "/control/stop", "Bearer " + kToken), kLoopback, texts);
  EXPECT_EQ(r.response.status, 405u) << "a link followed by a crawler stops nothing";
  EXPECT_FALSE(r.command);
  ASSERT_FALSE(r.response.headers.empty());
  EXPECT_EQ(r.response.headers.front(), (std::pair<std::string, std::string>{"Allow", "POST"}));
  r = route(request(http::Method::post, "/status.json", "Bearer " + kToken), kLoopback, texts);
  EXPECT_EQ(r.response.status, 405u);
  r = route(request(http::Method::get, "/nope"), kLoopback, texts);
  EXPECT_EQ(r.response.status, 404u);
  EXPECT_NE(r.response.body->find("/nope"), std::string::npos);
  EXPECT_EQ(route(request(http::Method::get, "/control/pause/"), kLoopback, texts).response.status, 404u);
}

TEST(OperatorApi, BeforeTheFirstStatusItSaysSo) {
  StatusTexts texts = published();
  texts.json = nullptr;
  texts.metrics = nullptr;
  EXPECT_EQ(route(request(http::Method::get, "/status.json"), kLoopback, texts).response.status, 503u);
  EXPECT_EQ(route(request(http::Method::get, "/metrics"), kLoopback, texts).response.status, 503u);
}

http::Request upgrade(const std::string& query, const std::string& origin = "", bool loopback = true) {
  http::Request r = request(http::Method::get, "/api/session");
  r.query = query;
  r.origin = origin;
  r.host = "127.0.0.1:8080";
  r.peer_is_loopback = loopback;
  r.websocket_upgrade = true;
  return r;
}

// The scene session's WebSocket: only with master.api, only as a WebSocket,
// from a browser only from this server's own page, with the token where there
// is one (as a header or in the query) and from this machine where there is none.
TEST(OperatorApi, TheSceneSessionsWebSocketIsOpenedOnlyByWhoMay) {
  const StatusTexts texts = published();
  OperatorAccess with_token = kLoopback;
  with_token.scene_sessions = true;
  OperatorAccess no_secret = kNoSecret;
  no_secret.scene_sessions = true;

  Routed r = route(upgrade("application=page&token=" + kToken, "http://127.0.0.1:8080"), with_token, texts);
  EXPECT_EQ(r.response.status, 101u);
  EXPECT_EQ(r.scene_session.value_or("(none)"), "page");
  http::Request bearer = upgrade("");
  bearer.authorization = "Bearer " + kToken;
  r = route(bearer, with_token, texts);
  EXPECT_EQ(r.scene_session.value_or("(none)"), "websocket") << "a name by default";
  r = route(upgrade("token=" + kToken + "x"), with_token, texts);
  EXPECT_EQ(r.response.status, 401u);
  EXPECT_FALSE(r.scene_session);
  r = route(upgrade("application=page"), with_token, texts);
  EXPECT_EQ(r.response.status, 401u) << "loopback too, where there is a token";
  r = route(upgrade("token=" + kToken, "https://127.0.0.1:8080"), with_token, texts);
  EXPECT_EQ(r.response.status, 101u) << "this server's page over https (a proxy in front)";
  r = route(upgrade("token=" + kToken, "http://evil.example"), with_token, texts);
  EXPECT_EQ(r.response.status, 403u) << "another site's page, with a token it somehow has";
  EXPECT_FALSE(r.scene_session);

  r = route(upgrade("application=script"), no_secret, texts);
  EXPECT_EQ(r.response.status, 101u) << "no secret: this machine's scripts, as on master.api";
  EXPECT_EQ(r.scene_session.value_or("(none)"), "script");
  r = route(upgrade("", "http://evil.example"), no_secret, texts);
  EXPECT_EQ(r.response.status, 403u) << "a page from anywhere, in a browser on this machine";
  r = route(upgrade("", "", false), no_secret, texts);
  EXPECT_EQ(r.response.status, 403u) << "another machine, with no token to give";
  http::Request rebound = upgrade("");
  rebound.host = "attacker.example:8080";
  rebound.origin = "http://attacker.example:8080";
  r = route(rebound, no_secret, texts);
  EXPECT_EQ(r.response.status, 403u) << "a page whose name was rebound to this machine";

  http::Request plain = upgrade("");
  plain.websocket_upgrade = false;
  r = route(plain, no_secret, texts);
  EXPECT_EQ(r.response.status, 426u);
  EXPECT_NE(r.response.body->find("WebSocket"), std::string::npos);
  r = route(upgrade(""), kNoSecret, texts);
  EXPECT_EQ(r.response.status, 404u) << "no master.api";
  EXPECT_NE(r.response.body->find("master.api"), std::string::npos);
  http::Request posted = upgrade("");
  posted.method = http::Method::post;
  EXPECT_EQ(route(posted, no_secret, texts).response.status, 405u);
}

}  // namespace
}  // namespace optique::master
