// The status server's shell on real loopback sockets, with small limits so
// that each takes milliseconds: answers, keep-alive, HEAD, and every limit a
// client can run into (size, time, connections, a stream left unread).

#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>

#include <thread>

#include "http/server.h"
#include "http_client.h"
#include "process.h"

namespace optique::http {
namespace {

using namespace std::chrono_literals;
using testing::RawClient;

class HttpServerTest : public ::testing::Test {
 protected:
  void start(ServerLimits limits) {
    server_.emplace(
        io_, limits,
        [this](const Request& request) {
          ++handled_;
          if (request.path == "/events") {
            Response stream;
            stream.event_stream = true;
            return stream;
          }
          return text_response(
              200, request.method_text + " " + request.path + " " + request.query + " [" + request.authorization + "]");
        },
        log_);
    auto port = server_->listen("127.0.0.1", 0);
    ASSERT_TRUE(port.ok()) << port.error();
    port_ = port.value();
    thread_ = std::thread([this] { io_.run(); });
  }
  void TearDown() override {
    if (server_) server_->stop();
    if (thread_.joinable()) thread_.join();
  }

  spdlog::logger log_{"test", std::make_shared<spdlog::sinks::null_sink_mt>()};
  boost::asio::io_context io_;
  std::optional<Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::atomic<int> handled_{0};
};

TEST_F(HttpServerTest, AnswersAndKeepsTheConnection) {
  start({});
  RawClient client(port_);
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(client.send("GET /a?b=1 HTTP/1.1\r\nHost: x\r\nAuthorization: Bearer t\r\n\r\n"));
  testing::HttpReply reply = client.read_reply(2s);
  ASSERT_TRUE(reply.error.empty()) << reply.error;
  EXPECT_EQ(reply.status, 200);
  EXPECT_EQ(reply.body, "GET /a b=1 [Bearer t]\n");
  EXPECT_EQ(reply.headers["cache-control"], "no-store");
  ASSERT_TRUE(client.send("HEAD /c HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(client.read_until("\r\n\r\n", 2s));
  reply = testing::parse_reply(client.received());
  EXPECT_EQ(reply.status, 200) << "the same connection answers again";
  EXPECT_EQ(reply.headers["content-length"], "12") << "HEAD: the length a GET would get (\"HEAD /c  []\\n\")";
  EXPECT_FALSE(client.read_until("HEAD /c", 200ms)) << "and no body";
  EXPECT_EQ(server_->counts().requests, 2u);
}

TEST_F(HttpServerTest, OversizedRequestsAreRefusedAndClosed) {
  ServerLimits limits;
  limits.max_header_bytes = 1024;
  limits.max_body_bytes = 16;
  start(limits);
  RawClient big_header(port_);
  ASSERT_TRUE(big_header.send("GET / HTTP/1.1\r\nHost: x\r\nX-Junk: " + std::string(4000, 'j') + "\r\n\r\n"));
  testing::HttpReply reply = testing::parse_reply(big_header.read_until_closed(2s));
  EXPECT_EQ(reply.status, 431);
  EXPECT_TRUE(big_header.closed_within(1s));
  RawClient big_body(port_);
  ASSERT_TRUE(big_body.send("POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\n" + std::string(100, 'b')));
  reply = testing::parse_reply(big_body.read_until_closed(2s));
  EXPECT_EQ(reply.status, 413);
  EXPECT_NE(reply.body.find("the limit is 16 bytes"), std::string::npos);
  RawClient garbage(port_);
  ASSERT_TRUE(garbage.send("\x16\x03\x01 this is no HTTP\r\n\r\n"));
  reply = testing::parse_reply(garbage.read_until_closed(2s));
  EXPECT_EQ(reply.status, 400);
  EXPECT_EQ(handled_, 0) << "none of them reached the handler";
  EXPECT_EQ(server_->counts().too_large, 2u);
  EXPECT_EQ(server_->counts().bad_requests, 1u);
}

TEST_F(HttpServerTest, ASlowClientIsClosed) {
  ServerLimits limits;
  limits.request_timeout = 200ms;
  start(limits);
  // Timed from before the connection: the server's clock starts when it accepts,
  // which a loaded machine may do well before this thread has sent anything.
  const auto sent = std::chrono::steady_clock::now();
  RawClient slow(port_);
  ASSERT_TRUE(slow.send("GET / HTTP/1.1\r\nHost:"));  // and nothing more
  EXPECT_TRUE(slow.closed_within(5s));
  const auto took = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - sent);
  EXPECT_GE(took.count(), 150);
  // Beast closes the socket when the time is up and only then runs the read's
  // handler, which counts it: the client may see the close first.
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().timed_out == 1u; }, 2s))
      << server_->counts().timed_out;
  // A kept-alive connection left idle is closed the same way.
  RawClient idle(port_);
  ASSERT_TRUE(idle.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_EQ(idle.read_reply(2s).status, 200);
  EXPECT_TRUE(idle.closed_within(5s));
}

TEST_F(HttpServerTest, OneConnectionTooManyIsToldToComeBack) {
  ServerLimits limits;
  limits.max_connections = 2;
  start(limits);
  RawClient a(port_);
  RawClient b(port_);
  ASSERT_TRUE(a.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(b.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_EQ(a.read_reply(2s).status, 200);
  EXPECT_EQ(b.read_reply(2s).status, 200);
  RawClient c(port_);
  const testing::HttpReply refused = testing::parse_reply(c.read_until_closed(2s));
  EXPECT_EQ(refused.status, 503);
  EXPECT_EQ(refused.headers.at("retry-after"), "1");
  EXPECT_EQ(server_->counts().refused_busy, 1u);
  // Room again once one leaves.
  ASSERT_TRUE(a.send("GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"));
  EXPECT_TRUE(a.closed_within(2s));
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().open == 1; }, 2s));
  EXPECT_EQ(testing::http_request(port_, "GET", "/again").status, 200);
}

TEST_F(HttpServerTest, EventStreamsGetEveryPublishAndAreClosedWhenTheyFallBehind) {
  ServerLimits limits;
  limits.max_queued_events = 4;
  start(limits);
  RawClient reader(port_);
  ASSERT_TRUE(reader.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(reader.read_until("text/event-stream", 2s)) << reader.received();
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams == 1; }, 2s));
  server_->publish(std::make_shared<const std::string>("{\"frame\":1}"));
  server_->publish(std::make_shared<const std::string>("{\"frame\":2}"));
  EXPECT_TRUE(reader.read_until("data: {\"frame\":1}\n\ndata: {\"frame\":2}\n\n", 2s)) << reader.received();
  // A stream that is never read: once the socket's buffers are full, events
  // queue; beyond four it is closed rather than held in memory without end.
  RawClient stuck(port_);
  ASSERT_TRUE(stuck.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams == 2; }, 2s));
  // The reader keeps up, on a thread of its own.
  std::atomic<bool> done{false};
  std::atomic<bool> reader_open{true};
  std::thread keep_up([&] {
    while (!done && reader_open) reader_open = reader.discard_for(20ms);
  });
  const auto big = std::make_shared<const std::string>(std::string(1 << 20, 'x'));
  for (int i = 0; i < 64 && server_->counts().streams_behind == 0; ++i) {
    server_->publish(big);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams_behind == 1; }, 2s));
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams == 1; }, 2s)) << "the reader stays";
  done = true;
  keep_up.join();
  EXPECT_TRUE(reader_open);
}

}  // namespace
}  // namespace optique::http
