// The status server's shell on real sockets, with small limits so that each
// takes milliseconds: answers, keep-alive, HEAD, and every limit a client can run
// into (size, time, connections, per address and those kept for loopback, a
// stream left unread, the kernel's buffer included); and who may connect
// (http/connection_budget.h), decided without sockets.

#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>

#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "http/connection_budget.h"
#include "http/server.h"
#include "http_client.h"
#include "process.h"
#include "websocket_client.h"

namespace optique::http {
namespace {

using namespace std::chrono_literals;
using testing::RawClient;

class HttpServerTest : public ::testing::Test {
 protected:
  void start(ServerLimits limits, const std::string& address = "127.0.0.1") {
    server_.emplace(
        io_, limits,
        [this](const Request& request) {
          ++handled_;
          if (request.path == "/events") {
            Response stream;
            stream.event_stream = true;
            return stream;
          }
          if (request.path == "/ws") {
            Response upgrade;
            upgrade.status = 101;
            upgrade.websocket = websocket_endpoint(request);
            return upgrade;
          }
          return text_response(
              200, request.method_text + " " + request.path + " " + request.query + " [" + request.authorization + "]");
        },
        log_);
    auto port = server_->listen(address, 0);
    ASSERT_TRUE(port.ok()) << port.error();
    port_ = port.value();
    thread_ = std::thread([this] { io_.run(); });
  }
  // Six connections, the last two kept for loopback, on every address (a client
  // from this machine's address that is not loopback is not a loopback peer).
  void start_for_remote_peers(std::size_t per_address) {
    ServerLimits limits;
    limits.max_connections = 6;
    limits.loopback_reserved = 2;
    limits.max_per_address = per_address;
    start(limits, "0.0.0.0");
  }
  // `count` connections from `remote` that say nothing, as slow clients
  // re-opened as they close, once the server holds them all.
  std::vector<std::unique_ptr<RawClient>> hold(const testing::ClientOptions& remote, std::size_t count) {
    std::vector<std::unique_ptr<RawClient>> held;
    for (std::size_t i = 0; i < count; ++i) {
      held.push_back(std::make_unique<RawClient>(port_, remote));
      EXPECT_TRUE(held.back()->connected());
    }
    EXPECT_TRUE(testing::poll_until([&] { return server_->counts().open == count; }, 2s));
    return held;
  }
  // An echo: "close" closes it, "flood N" sends N messages of 1 KiB at once;
  // what it heard and why it closed are kept.
  std::shared_ptr<WebSocketEndpoint> websocket_endpoint(const Request& request) {
    auto endpoint = std::make_shared<WebSocketEndpoint>();
    endpoint->max_message_bytes = 1024;
    endpoint->max_queued_bytes = 64 << 10;
    auto peer = std::make_shared<std::shared_ptr<WebSocketPeer>>();
    upgrades_.push_back(request.origin + " " + (request.peer_is_loopback ? "loopback" : "remote"));
    endpoint->opened = [peer](std::shared_ptr<WebSocketPeer> opened) { *peer = std::move(opened); };
    endpoint->received = [this, peer](std::string text) {
      const std::string_view said(text);
      if (said == "close") {
        (*peer)->close("asked to");
      } else if (said.substr(0, 6) == "flood ") {
        for (int i = std::stoi(std::string(said.substr(6))); i > 0; --i) (*peer)->send(std::string(1024, 'f'));
        flood_queued_ = (*peer)->queued_bytes();
      } else {
        (*peer)->send("echo " + text);
      }
    };
    endpoint->closed = [this, peer](const std::string& reason) {
      const std::lock_guard lock(mutex_);
      closed_reasons_.push_back(reason);
      peer->reset();  // the endpoint and its peer hold each other until now
    };
    return endpoint;
  }
  std::vector<std::string> closed_reasons() {
    const std::lock_guard lock(mutex_);
    return closed_reasons_;
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
  std::vector<std::string> upgrades_;  // on the server's thread
  std::atomic<std::size_t> flood_queued_{0};
  std::mutex mutex_;
  std::vector<std::string> closed_reasons_;
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
  // 64 KiB a time: a status is some KiB; the stream's send buffer is 64 KiB.
  const auto big = std::make_shared<const std::string>(std::string(64 << 10, 'x'));
  for (int i = 0; i < 200 && server_->counts().streams_behind == 0; ++i) {
    server_->publish(big);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams_behind == 1; }, 2s));
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().streams == 1; }, 2s)) << "the reader stays";
  done = true;
  keep_up.join();
  EXPECT_TRUE(reader_open);
}

TEST_F(HttpServerTest, TheHeaderLimitCountsTheWholeHeader) {
  ServerLimits limits;
  limits.max_header_bytes = 1024;
  start(limits);
  // Many small fields, sent in pieces as they would trickle in: Beast alone
  // bounded only what it had not parsed yet, and let twice the limit through.
  const std::string start_line = "GET /small HTTP/1.1\r\nHost: x\r\n";
  std::string fields;
  for (int i = 0; fields.size() < 2000; ++i) fields += "X-" + std::to_string(i) + ": y\r\n";
  RawClient trickled(port_);
  ASSERT_TRUE(trickled.send(start_line));
  for (std::size_t at = 0; at < fields.size(); at += 100) {
    ASSERT_TRUE(trickled.send(fields.substr(at, 100)));
    std::this_thread::sleep_for(2ms);
  }
  (void)trickled.send("\r\n");
  const testing::HttpReply refused = testing::parse_reply(trickled.read_until_closed(2s));
  EXPECT_EQ(refused.status, 431) << refused.body;
  EXPECT_NE(refused.body.find("the limit is 1024 bytes"), std::string::npos) << refused.body;
  // Exactly the limit, from the request line to the blank line: taken; a byte more: not.
  const auto header_of = [&](std::size_t bytes) {
    std::string header = "GET /exact HTTP/1.1\r\nHost: x\r\nX-Pad: ";
    header += std::string(bytes - header.size() - 4, 'p');
    return header + "\r\n\r\n";
  };
  ASSERT_EQ(header_of(1024).size(), 1024u);
  RawClient exact(port_);
  ASSERT_TRUE(exact.send(header_of(1024)));
  EXPECT_EQ(exact.read_reply(2s).status, 200);
  RawClient over(port_);
  ASSERT_TRUE(over.send(header_of(1025)));
  EXPECT_EQ(testing::parse_reply(over.read_until_closed(2s)).status, 431);
  // Requests kept alive and pipelined are each counted on their own.
  RawClient pipelined(port_);
  ASSERT_TRUE(pipelined.send(header_of(1000) + header_of(1000)));
  EXPECT_EQ(pipelined.read_reply(2s).status, 200);
  EXPECT_EQ(pipelined.read_reply(2s).status, 200);
  EXPECT_EQ(server_->counts().too_large, 2u);
}

TEST_F(HttpServerTest, EveryAnswerForbidsFramingAndSniffing) {
  ServerLimits limits;
  limits.max_connections = 1;
  start(limits);
  RawClient kept(port_);
  ASSERT_TRUE(kept.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  const testing::HttpReply answered = kept.read_reply(2s);
  EXPECT_EQ(answered.status, 200);
  RawClient refused_client(port_);
  const testing::HttpReply refused = testing::parse_reply(refused_client.read_until_closed(2s));
  EXPECT_EQ(refused.status, 503);
  for (const auto& reply : {answered, refused}) {
    EXPECT_EQ(reply.headers.count("x-frame-options") ? reply.headers.at("x-frame-options") : "", "DENY");
    EXPECT_EQ(reply.headers.count("x-content-type-options") ? reply.headers.at("x-content-type-options") : "",
              "nosniff");
  }
  ASSERT_TRUE(kept.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(kept.read_until("\r\n\r\n", 2s));
  const std::string stream_head = kept.received();
  EXPECT_NE(stream_head.find("X-Frame-Options: DENY\r\n"), std::string::npos) << stream_head;
  EXPECT_NE(stream_head.find("X-Content-Type-Options: nosniff\r\n"), std::string::npos) << stream_head;
}

// A stream whose client never reads holds little: its socket's send buffer is
// kept small, the queue behind it is bounded, and closing it drops what the
// kernel held. Before, the kernel took up to 4 MiB for it first, minutes of
// updates, before the queue even began to grow.
TEST_F(HttpServerTest, AStreamThatIsNeverReadIsClosedBeforeItHoldsMuch) {
  ServerLimits limits;
  limits.max_queued_events = 8;
  limits.write_timeout = 10s;  // the queue, not the time, closes it here
  start(limits);
  testing::ClientOptions small;
  small.receive_buffer = 4096;
  RawClient stuck(port_, small);
  ASSERT_TRUE(stuck.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(testing::poll_until([&] { return server_->counts().streams == 1; }, 2s));
  const auto event = std::make_shared<const std::string>(std::string(1024, 'e'));
  std::size_t published = 0;
  const auto deadline = std::chrono::steady_clock::now() + 8s;
  while (server_->counts().streams_behind == 0 && std::chrono::steady_clock::now() < deadline) {
    // In bursts the size of the queue, each given time to reach the socket.
    for (int i = 0; i < 8; ++i) server_->publish(event);
    published += 8;
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_EQ(server_->counts().streams_behind, 1u) << published << " events of 1 KiB published";
  // 64 KiB of send buffer (32 KiB doubled), the client's few KiB, the queue,
  // and a burst in flight: well under 512 KiB. It was about 4 MiB.
  EXPECT_LT(published * 1030, 512u << 10) << published << " events of 1 KiB published before it was closed";
  EXPECT_TRUE(stuck.closed_within(2s));
}

TEST_F(HttpServerTest, AWebSocketCarriesTextBothWaysAndClosesWithItsReason) {
  start({});
  testing::WebSocketClient client(port_, "/ws", {{"Origin", "http://127.0.0.1"}});
  ASSERT_TRUE(client.open()) << client.error();
  EXPECT_EQ(client.upgrade_status(), 101);
  ASSERT_TRUE(client.send("hello"));
  EXPECT_EQ(client.receive(2s).value_or("(none)"), "echo hello");
  ASSERT_TRUE(client.send("ünïcødé"));
  EXPECT_EQ(client.receive(2s).value_or("(none)"), "echo ünïcødé");
  EXPECT_EQ(server_->counts().websockets, 1u);
  ASSERT_TRUE(client.send("close"));
  EXPECT_FALSE(client.receive(2s));
  EXPECT_TRUE(client.closed());
  EXPECT_EQ(client.close_code(), 1000);
  EXPECT_EQ(client.close_reason(), "asked to");
  ASSERT_TRUE(testing::poll_until([&] { return closed_reasons().size() == 1; }, 2s));
  EXPECT_EQ(closed_reasons()[0], "asked to");
  EXPECT_TRUE(testing::poll_until([&] { return server_->counts().websockets == 0; }, 2s));
  // The client closing is heard too.
  testing::WebSocketClient leaving(port_, "/ws");
  ASSERT_TRUE(leaving.open()) << leaving.error();
  leaving.close();
  ASSERT_TRUE(testing::poll_until([&] { return closed_reasons().size() == 2; }, 2s));
  EXPECT_EQ(closed_reasons()[1], "the client closed the WebSocket (code 1000)");
  EXPECT_EQ(upgrades_.front(), "http://127.0.0.1 loopback") << "the handler sees the Origin and the peer";
  // A plain request to the same path is no WebSocket.
  EXPECT_EQ(testing::http_request(port_, "GET", "/ws").status, 500);
}

TEST_F(HttpServerTest, AWebSocketThatBreaksItsBoundsIsClosed) {
  ServerLimits limits;
  limits.websocket_idle = 300ms;
  start(limits);
  testing::WebSocketClient big(port_, "/ws");
  ASSERT_TRUE(big.open()) << big.error();
  ASSERT_TRUE(big.send(std::string(1025, 'b')));  // the endpoint takes 1 KiB
  EXPECT_FALSE(big.receive(2s));
  EXPECT_EQ(big.close_code(), 1009) << big.error();
  testing::WebSocketClient binary(port_, "/ws");
  ASSERT_TRUE(binary.send_binary("\x01\x02"));
  EXPECT_FALSE(binary.receive(2s));
  EXPECT_EQ(binary.close_code(), 1003) << binary.error();
  EXPECT_EQ(binary.close_reason(), "this WebSocket takes text messages only");
  // One that never reads, not even a ping, is closed after the idle time; one
  // that reads stays (the server's pings are answered while it reads).
  testing::WebSocketClient silent(port_, "/ws");
  testing::WebSocketClient listening(port_, "/ws");
  ASSERT_TRUE(silent.open() && listening.open());
  EXPECT_FALSE(listening.receive(900ms)) << "nothing to hear, and no close";
  EXPECT_FALSE(listening.closed()) << listening.error();
  ASSERT_TRUE(testing::poll_until([&] { return closed_reasons().size() == 3; }, 2s));
  const auto reasons = closed_reasons();
  EXPECT_EQ(reasons[0], "a message over 1024 bytes");
  EXPECT_EQ(reasons[1], "this WebSocket takes text messages only");
  EXPECT_EQ(reasons[2], "it answered nothing, not even a ping, for 300 ms");
  // One that stops reading while the endpoint sends is closed once 64 KiB wait
  // beyond the kernel's buffers, rather than held without end.
  testing::WebSocketClient stalled(port_, "/ws");
  ASSERT_TRUE(stalled.open());
  ASSERT_TRUE(stalled.send("flood 2000"));  // 2 MiB, never read
  ASSERT_TRUE(testing::poll_until([&] { return closed_reasons().size() == 4; }, 3s));
  EXPECT_EQ(closed_reasons()[3].rfind("it stopped reading: ", 0), 0u) << closed_reasons()[3];
  EXPECT_EQ(flood_queued_, 2000u * 1024) << "counted as it was sent, for its owner to see at once";
  EXPECT_EQ(server_->counts().streams_behind, 1u);
}

TEST_F(HttpServerTest, APeerNotOnLoopbackIsHeldToItsShareAndLoopbackAlwaysGetsIn) {
  testing::ClientOptions remote;
  remote.address = testing::non_loopback_address();
  if (remote.address.empty()) GTEST_SKIP() << "this machine has no address but loopback";
  start_for_remote_peers(3);
  const auto held = hold(remote, 3);
  RawClient fourth(port_, remote);
  const testing::HttpReply crowded = testing::parse_reply(fourth.read_until_closed(2s));
  EXPECT_EQ(crowded.status, 503);
  EXPECT_NE(crowded.body.find("from your address (3)"), std::string::npos) << crowded.body;
  EXPECT_EQ(server_->counts().refused_address, 1u);
  // Loopback is not held to the share: it fills the rest, the kept slots too.
  std::vector<std::unique_ptr<RawClient>> local;
  for (int i = 0; i < 3; ++i) {
    local.push_back(std::make_unique<RawClient>(port_));
    ASSERT_TRUE(local.back()->send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
    EXPECT_EQ(local.back()->read_reply(2s).status, 200) << i;
  }
  RawClient over(port_);
  EXPECT_EQ(testing::parse_reply(over.read_until_closed(2s)).status, 503) << "six are open";
  EXPECT_EQ(server_->counts().refused_busy, 1u);
}

TEST_F(HttpServerTest, TheLastSlotsAreKeptForLoopback) {
  testing::ClientOptions remote;
  remote.address = testing::non_loopback_address();
  if (remote.address.empty()) GTEST_SKIP() << "this machine has no address but loopback";
  start_for_remote_peers(16);
  auto held = hold(remote, 4);
  RawClient fifth(port_, remote);
  EXPECT_EQ(testing::parse_reply(fifth.read_until_closed(2s)).status, 503) << "the last two are loopback's";
  EXPECT_EQ(server_->counts().refused_busy, 1u);
  // The operator on the master's machine still gets in, twice.
  EXPECT_EQ(testing::http_request(port_, "GET", "/").status, 200);
  RawClient a(port_);
  RawClient b(port_);
  ASSERT_TRUE(a.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  ASSERT_TRUE(b.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_EQ(a.read_reply(2s).status, 200);
  EXPECT_EQ(b.read_reply(2s).status, 200);
  // A remote slot freed is a remote slot again.
  held.pop_back();
  ASSERT_TRUE(testing::poll_until([&] { return server_->counts().open == 5; }, 2s));
  RawClient again(port_, remote);
  ASSERT_TRUE(again.send("GET / HTTP/1.1\r\nHost: x\r\n\r\n"));
  EXPECT_EQ(again.read_reply(2s).status, 200);
}

TEST(ConnectionBudget, OneAddressGetsItsShareAndAnIpv6Slash64CountsAsOne) {
  namespace ip = boost::asio::ip;
  ConnectionBudget budget(100, 2, 8);
  const auto a = ip::make_address("192.0.2.7");
  EXPECT_EQ(budget.admit(a), Admission::admitted);
  EXPECT_EQ(budget.admit(ip::make_address("::ffff:192.0.2.7")), Admission::admitted) << "the same, mapped";
  EXPECT_EQ(budget.admit(a), Admission::too_many_from_address);
  EXPECT_EQ(budget.admit(ip::make_address("192.0.2.8")), Admission::admitted);
  budget.release(a);
  EXPECT_EQ(budget.admit(a), Admission::admitted) << "released: room again";
  EXPECT_EQ(budget.admit(ip::make_address("2001:db8:1:2::1")), Admission::admitted);
  EXPECT_EQ(budget.admit(ip::make_address("2001:db8:1:2:ffff::9")), Admission::admitted);
  EXPECT_EQ(budget.admit(ip::make_address("2001:db8:1:2::3")), Admission::too_many_from_address) << "one /64";
  EXPECT_EQ(budget.admit(ip::make_address("2001:db8:1:3::1")), Admission::admitted) << "another /64";
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(budget.admit(ip::make_address(i % 2 == 0 ? "127.0.0.1" : "::1")), Admission::admitted);
  }
  EXPECT_EQ(budget.admit(ip::make_address("::ffff:127.0.0.5")), Admission::admitted) << "loopback, mapped";
  EXPECT_EQ(budget.open(), 27u);
}

TEST(ConnectionBudget, TheLastSlotsAreLoopbacksAndAtMostHalf) {
  namespace ip = boost::asio::ip;
  ConnectionBudget budget(10, 100, 3);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(budget.admit(ip::make_address("198.51.100." + std::to_string(i))), Admission::admitted);
  }
  EXPECT_EQ(budget.admit(ip::make_address("198.51.100.99")), Admission::busy);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(budget.admit(ip::make_address("127.0.0.1")), Admission::admitted);
  EXPECT_EQ(budget.admit(ip::make_address("127.0.0.1")), Admission::busy) << "all ten taken";
  ConnectionBudget small(2, 100, 8);
  EXPECT_EQ(small.admit(ip::make_address("198.51.100.1")), Admission::admitted) << "one of two kept, not both";
  EXPECT_EQ(small.admit(ip::make_address("198.51.100.2")), Admission::busy);
  EXPECT_EQ(small.admit(ip::make_address("127.0.0.1")), Admission::admitted);
}

}  // namespace
}  // namespace optique::http
