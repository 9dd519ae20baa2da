// The status server's answers, decided without a network: which path gives
// what, which method is allowed, and who may read or control.

#include <gtest/gtest.h>

#include "master/operator_api.h"
#include "master/status_metrics.h"

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
  return {std::make_shared<const std::string>("<html>page</html>"), std::make_shared<const std::string>("{\"a\":1}"),
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
    r = route(request(http::Method::get, path, "bearer  " + kToken + " "), kBeyondLoopback, texts);
    EXPECT_TRUE(r.response.status == 200u || r.response.event_stream) << path << ": the scheme in any case";
  }
  // The page holds no data: it is served to anyone, and asks for the token.
  EXPECT_EQ(route(request(http::Method::get, "/"), kBeyondLoopback, texts).response.status, 200u);
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

}  // namespace
}  // namespace optique::master
