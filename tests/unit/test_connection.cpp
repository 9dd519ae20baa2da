// net::Connection over a real loopback socket: messages whole and in order
// however the bytes arrive, each with the kernel's receive time, and the close
// reasons a peer's departure gives.

#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "clock/clock.h"
#include "net/connection.h"
#include "net/envelope.h"

namespace optique::net {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;

struct Received {
  wire::Envelope message;
  clock::Nanos received = 0;  // the kernel's stamp
  clock::Nanos handled = 0;   // when the handler ran
};

// A Connection on the accepting side; the test writes raw frames to `client`.
struct Loopback {
  asio::io_context io;
  tcp::socket client{io};
  std::shared_ptr<Connection> server;
  std::vector<Received> received;
  std::string closed_reason;
  std::vector<std::uint32_t> oversized;  // the lengths of messages passed over
  std::function<void()> after_message;   // run by the handler after each

  Loopback() {
    tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    client.connect(acceptor.local_endpoint());
    server = Connection::create(acceptor.accept(), kDefaultMaxPayloadBytes);
    server->start({[this](wire::Envelope& message, clock::Nanos at) {
                     received.push_back({message, at, clock::monotonic_now()});
                     if (after_message) after_message();
                   },
                   [this](const std::string& reason) { closed_reason = reason; },
                   [this](std::uint32_t bytes, std::uint32_t) { oversized.push_back(bytes); }});
  }

  // Frames `count` pings (t1 = 1, 2, …) with sequence numbers from `first`.
  static std::vector<std::uint8_t> pings(std::uint64_t first, int count, std::size_t padding = 0) {
    std::vector<std::uint8_t> bytes;
    for (int i = 0; i < count; ++i) {
      wire::Envelope envelope;
      envelope.set_protocol_version(kProtocolVersion);
      envelope.set_sequence(first + static_cast<std::uint64_t>(i));
      envelope.mutable_ping()->set_t1(static_cast<std::int64_t>(first) + i);
      if (padding > 0) {
        // A hello is the one body with free text: padding for a large frame.
        envelope.mutable_hello()->set_node_id(std::string(padding, 'x'));
      }
      append_envelope(bytes, envelope);
    }
    return bytes;
  }

  void run_until(const std::function<bool()>& done) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!done() && std::chrono::steady_clock::now() < give_up) {
      if (io.stopped()) io.restart();  // out of work a moment (a held connection waits for nothing)
      io.run_for(std::chrono::milliseconds(5));
    }
  }
};

TEST(Connection, AMessageCarriesTheTimeTheKernelReceivedItNotTheTimeItWasRead) {
  Loopback loop;
  // The kernel starts stamping a moment after the first socket in the system
  // asks (it patches its receive path from a work queue); until then a message
  // carries the time it was read.
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const clock::Nanos before = clock::monotonic_now();
  asio::write(loop.client, asio::buffer(Loopback::pings(1, 1)));
  // The io thread is busy elsewhere for 50 ms before it reads.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  loop.run_until([&] { return !loop.received.empty(); });
  ASSERT_EQ(loop.received.size(), 1u);
  const Received& r = loop.received[0];
  EXPECT_EQ(r.message.ping().t1(), 1);
  // Slack for mapping the kernel's wall-clock stamp onto the monotonic clock.
  EXPECT_GE(r.received, before - 100 * clock::kNanosPerMicro);
  EXPECT_LE(r.received, r.handled - 40 * clock::kNanosPerMilli)
      << "stamped " << (r.handled - r.received) / 1e6 << " ms before it was handled";
}

TEST(Connection, ABurstLargerThanTheReadBufferArrivesWholeAndInOrder) {
  Loopback loop;
  // 2000 small frames and then frames of 200 KiB each, more than one read holds,
  // written at once: the connection must read until the socket is empty.
  std::vector<std::uint8_t> bytes = Loopback::pings(1, 2000);
  const std::vector<std::uint8_t> large = Loopback::pings(2001, 5, 200 * 1024);
  bytes.insert(bytes.end(), large.begin(), large.end());
  std::thread writer([&] { asio::write(loop.client, asio::buffer(bytes)); });
  loop.run_until([&] { return loop.received.size() == 2005; });
  writer.join();
  ASSERT_EQ(loop.received.size(), 2005u) << loop.closed_reason;
  for (std::size_t i = 0; i < 2000; ++i) ASSERT_EQ(loop.received[i].message.ping().t1(), static_cast<int>(i) + 1);
  for (std::size_t i = 2000; i < 2005; ++i) {
    ASSERT_TRUE(loop.received[i].message.has_hello());
    EXPECT_EQ(loop.received[i].message.hello().node_id().size(), 200u * 1024);
  }
  // In order, but for the jitter of mapping the kernel's wall-clock stamp onto
  // the monotonic clock (two clock reads: tens of nanoseconds).
  for (std::size_t i = 1; i < loop.received.size(); ++i) {
    EXPECT_GE(loop.received[i].received, loop.received[i - 1].received - clock::kNanosPerMicro)
        << "receive times go back at " << i;
  }
  EXPECT_TRUE(loop.closed_reason.empty()) << loop.closed_reason;
}

// A connection that skips oversized messages passes over one (its bytes
// dropped as they come, in any pieces), says how long it was, and reads the
// next in the sequence; without skipping, one closes it.
TEST(Connection, AnOversizedMessageIsPassedOverWhenAskedAndClosesOtherwise) {
  {
    Loopback loop;
    loop.server->set_max_payload_bytes(64 * 1024);
    loop.server->skip_oversized();
    std::vector<std::uint8_t> bytes = Loopback::pings(1, 1);
    const std::vector<std::uint8_t> large = Loopback::pings(2, 1, 300 * 1024);
    const std::vector<std::uint8_t> after = Loopback::pings(3, 2);
    bytes.insert(bytes.end(), large.begin(), large.end());
    bytes.insert(bytes.end(), after.begin(), after.end());
    std::thread writer([&] {
      // In pieces that split the header and the payload anywhere.
      for (std::size_t at = 0; at < bytes.size(); at += 7001) {
        asio::write(loop.client, asio::buffer(bytes.data() + at, std::min<std::size_t>(7001, bytes.size() - at)));
      }
    });
    loop.run_until([&] { return loop.received.size() == 3 || !loop.closed_reason.empty(); });
    writer.join();
    ASSERT_EQ(loop.received.size(), 3u) << loop.closed_reason;
    EXPECT_EQ(loop.received[0].message.ping().t1(), 1);
    EXPECT_EQ(loop.received[1].message.ping().t1(), 3);
    EXPECT_EQ(loop.received[2].message.ping().t1(), 4);
    ASSERT_EQ(loop.oversized.size(), 1u);
    EXPECT_GT(loop.oversized[0], 300u * 1024);
    EXPECT_TRUE(loop.closed_reason.empty()) << loop.closed_reason;
  }
  {
    Loopback loop;
    loop.server->set_max_payload_bytes(64 * 1024);
    asio::write(loop.client, asio::buffer(Loopback::pings(1, 1, 300 * 1024)));
    loop.run_until([&] { return !loop.closed_reason.empty(); });
    EXPECT_NE(loop.closed_reason.find("exceeds the maximum of 65536"), std::string::npos) << loop.closed_reason;
    EXPECT_TRUE(loop.oversized.empty());
  }
}

// A held connection hands on nothing, neither what its reader holds already
// nor what comes meanwhile; let go, all of it comes, in order, and reading
// goes on.
TEST(Connection, AHeldConnectionHandsOnNothingUntilLetGo) {
  Loopback loop;
  // Held by its own handler after the first of three frames read at once.
  loop.after_message = [&] {
    if (loop.received.size() == 1) loop.server->hold_reading(true);
  };
  asio::write(loop.client, asio::buffer(Loopback::pings(1, 3)));
  loop.run_until([&] { return !loop.received.empty(); });
  asio::write(loop.client, asio::buffer(Loopback::pings(4, 2)));
  const auto settle = std::chrono::steady_clock::now() + std::chrono::milliseconds(50);
  loop.run_until([&] { return std::chrono::steady_clock::now() > settle; });
  EXPECT_EQ(loop.received.size(), 1u) << "held";
  loop.server->hold_reading(false);
  loop.run_until([&] { return loop.received.size() == 5; });
  ASSERT_EQ(loop.received.size(), 5u) << loop.closed_reason;
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(loop.received[i].message.ping().t1(), static_cast<int>(i) + 1);
  // Held while it waits for bytes, then let go twice over: each frame once.
  loop.server->hold_reading(true);
  asio::write(loop.client, asio::buffer(Loopback::pings(6, 1)));
  const auto again = std::chrono::steady_clock::now() + std::chrono::milliseconds(50);
  loop.run_until([&] { return std::chrono::steady_clock::now() > again; });
  EXPECT_EQ(loop.received.size(), 5u) << "held";
  loop.server->hold_reading(false);
  loop.server->hold_reading(false);
  loop.run_until([&] { return loop.received.size() == 6; });
  asio::write(loop.client, asio::buffer(Loopback::pings(7, 1)));
  loop.run_until([&] { return loop.received.size() == 7; });
  ASSERT_EQ(loop.received.size(), 7u) << loop.closed_reason;
  EXPECT_EQ(loop.received[6].message.ping().t1(), 7);
  EXPECT_TRUE(loop.closed_reason.empty()) << loop.closed_reason;
}

TEST(Connection, NoMessageReachesItsHandlerBeforeStartReturns) {
  asio::io_context io;
  tcp::acceptor acceptor(io, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  tcp::socket client(io);
  client.connect(acceptor.local_endpoint());
  asio::write(client, asio::buffer(Loopback::pings(1, 3)));
  auto server = Connection::create(acceptor.accept(), kDefaultMaxPayloadBytes);
  int handled = 0;
  server->start({[&](wire::Envelope&, clock::Nanos) { ++handled; }, [](const std::string&) {}, {}});
  EXPECT_EQ(handled, 0);
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (handled < 3 && std::chrono::steady_clock::now() < give_up) io.run_for(std::chrono::milliseconds(5));
  EXPECT_EQ(handled, 3) << "what was sent before start() is read after it";
}

TEST(Connection, APeerThatClosesIsReportedOnce) {
  Loopback loop;
  asio::write(loop.client, asio::buffer(Loopback::pings(1, 2)));
  loop.client.close();
  loop.run_until([&] { return !loop.closed_reason.empty(); });
  EXPECT_EQ(loop.received.size(), 2u) << "what came before the close is still delivered";
  EXPECT_EQ(loop.closed_reason, "peer closed the connection");
  EXPECT_FALSE(loop.server->is_open());
}

TEST(Connection, BytesOutOfSequenceCloseTheConnectionWithTheReason) {
  Loopback loop;
  asio::write(loop.client, asio::buffer(Loopback::pings(2, 1)));
  loop.run_until([&] { return !loop.closed_reason.empty(); });
  EXPECT_TRUE(loop.received.empty());
  EXPECT_EQ(loop.closed_reason, "message out of sequence (got 2, expected 1)");
}

}  // namespace
}  // namespace optique::net

namespace optique::net {
namespace {

// Frames `count` pings sealed with `sealer`, sequence numbers from `first`.
std::vector<std::uint8_t> sealed_pings(Sealer& sealer, std::uint64_t first, int count) {
  std::vector<std::uint8_t> bytes;
  for (int i = 0; i < count; ++i) {
    const std::vector<std::uint8_t> plain = Loopback::pings(first + static_cast<std::uint64_t>(i), 1);
    const auto payload = std::span(plain).subspan(kFrameHeaderBytes);
    append_frame(bytes, sealer.seal(payload));
  }
  return bytes;
}

const SessionKeys& test_keys() {
  static const SessionKeys keys =
      derive_session_keys(Secret{std::vector<std::uint8_t>(32, 1)}, std::vector<std::uint8_t>(32, 2),
                          std::vector<std::uint8_t>(32, 3), "wall", kProtocolVersion);
  return keys;
}

// After protect(): sealed frames in order are taken; a plain one, a replayed
// one, or one sealed with another key closes the connection, and nothing of it
// reaches the handler.
TEST(Connection, AProtectedConnectionTakesOnlyItsSessionsFramesInOrder) {
  for (const std::string attack : {"plain", "replayed", "other key", "reordered"}) {
    SCOPED_TRACE(attack);
    Loopback loop;
    loop.server->protect(test_keys().to_node, test_keys().to_master, false);
    Sealer node(test_keys().to_master);
    const auto good = sealed_pings(node, 1, 2);
    asio::write(loop.client, asio::buffer(good));
    loop.run_until([&] { return loop.received.size() == 2; });
    ASSERT_EQ(loop.received.size(), 2u);
    std::vector<std::uint8_t> bad;
    if (attack == "plain") {
      bad = Loopback::pings(3, 1);
    } else if (attack == "replayed") {
      bad = good;
    } else if (attack == "other key") {
      Sealer forger(derive_session_keys(Secret{std::vector<std::uint8_t>(32, 9)}, std::vector<std::uint8_t>(32, 2),
                                        std::vector<std::uint8_t>(32, 3), "wall", kProtocolVersion)
                        .to_master);
      (void)forger.seal(std::vector<std::uint8_t>{});
      (void)forger.seal(std::vector<std::uint8_t>{});
      bad = sealed_pings(forger, 3, 1);
    } else {
      (void)node.seal(std::vector<std::uint8_t>{});  // the third frame is skipped: the fourth comes first
      bad = sealed_pings(node, 4, 1);
    }
    asio::write(loop.client, asio::buffer(bad));
    loop.run_until([&] { return !loop.closed_reason.empty(); });
    EXPECT_TRUE(loop.closed_reason.find("failed authentication") != std::string::npos ||
                loop.closed_reason.find("no room for its tag") != std::string::npos)
        << loop.closed_reason;
    EXPECT_EQ(loop.received.size(), 2u) << "nothing of it handed on";
  }
}

// What the server sends after protect() is sealed: the peer's opener opens it,
// and the plain bytes are not on the wire.
TEST(Connection, WhatAProtectedConnectionSendsIsSealed) {
  Loopback loop;
  loop.server->protect(test_keys().to_node, test_keys().to_master, false);
  wire::Envelope message;
  message.mutable_goodbye()->set_reason("a reason anyone could read");
  loop.server->send(message);
  std::vector<std::uint8_t> bytes;
  loop.run_until([&] {
    std::array<std::uint8_t, 4096> buffer{};
    boost::system::error_code error;
    loop.client.non_blocking(true);
    const std::size_t got = loop.client.read_some(asio::buffer(buffer), error);
    if (!error) bytes.insert(bytes.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(got));
    return !bytes.empty();
  });
  const DecodedFrame frame = decode_frame(bytes, kDefaultMaxPayloadBytes);
  ASSERT_EQ(frame.status, DecodeStatus::good);
  EXPECT_EQ(std::string(frame.payload.begin(), frame.payload.end()).find("anyone could read"), std::string::npos);
  Opener opener(test_keys().to_node);
  const auto opened = opener.open(frame.payload);
  ASSERT_TRUE(opened) << opened.error();
  const auto parsed = parse_envelope(opened.value());
  ASSERT_TRUE(parsed);
  EXPECT_EQ(parsed.value().goodbye().reason(), "a reason anyone could read");
}

// A message serialized once for several peers: each is sent it with its own
// sequence (one after the other here), plain or sealed, and reads it whole.
TEST(Connection, AMessageSerializedOnceArrivesWithEachSendsSequence) {
  wire::Envelope body;
  body.mutable_frame_begin()->set_frame_id(42);
  body.mutable_frame_begin()->set_state_hash(0x1234);
  std::vector<std::uint8_t> bytes(body.ByteSizeLong());
  (void)body.SerializeToArray(bytes.data(), static_cast<int>(bytes.size()));
  for (const bool sealed : {false, true}) {
    Loopback loop;
    if (sealed) loop.server->protect(test_keys().to_node, test_keys().to_master, false);
    wire::Envelope first;
    first.mutable_ping()->set_t1(1);
    loop.server->send(first);
    loop.server->send_serialized(bytes);
    loop.server->send_serialized(bytes);
    std::vector<std::uint8_t> got;
    std::vector<wire::Envelope> read;
    Opener opener(test_keys().to_node);
    loop.run_until([&] {
      std::array<std::uint8_t, 4096> buffer{};
      boost::system::error_code error;
      loop.client.non_blocking(true);
      const std::size_t n = loop.client.read_some(asio::buffer(buffer), error);
      if (!error) got.insert(got.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
      for (DecodedFrame frame = decode_frame(got, kDefaultMaxPayloadBytes); frame.status == DecodeStatus::good;
           frame = decode_frame(got, kDefaultMaxPayloadBytes)) {
        std::vector<std::uint8_t> payload(frame.payload.begin(), frame.payload.end());
        got.erase(got.begin(), got.begin() + static_cast<std::ptrdiff_t>(frame.consumed));
        if (sealed) {
          auto opened = opener.open(payload);
          EXPECT_TRUE(opened) << opened.error();
          if (!opened) return true;
          payload = std::move(opened).value();
        }
        auto parsed = parse_envelope(payload);
        EXPECT_TRUE(parsed) << parsed.error();
        if (parsed) read.push_back(std::move(parsed).value());
      }
      return read.size() == 3;
    });
    ASSERT_EQ(read.size(), 3u) << (sealed ? "sealed" : "plain");
    for (std::size_t i = 1; i < 3; ++i) {
      EXPECT_EQ(read[i].sequence(), read[0].sequence() + i) << i;
      EXPECT_EQ(read[i].protocol_version(), kProtocolVersion);
      ASSERT_TRUE(read[i].has_frame_begin());
      EXPECT_EQ(read[i].frame_begin().frame_id(), 42u);
      EXPECT_EQ(read[i].frame_begin().state_hash(), 0x1234u);
    }
  }
}

}  // namespace
}  // namespace optique::net
