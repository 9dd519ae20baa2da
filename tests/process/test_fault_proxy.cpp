// The fault proxy against a local echo server: what it forwards arrives intact and
// in order under every fault, and its resets and refusals reach the client.

#include "fault_proxy.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/write.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <thread>
#include <vector>

namespace optique::testing {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;
using boost::system::error_code;
using Clock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;
using namespace std::chrono_literals;

Bytes random_bytes(std::size_t size, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> byte(0, 255);
  Bytes bytes(size);
  for (std::uint8_t& b : bytes) b = static_cast<std::uint8_t>(byte(rng));
  return bytes;
}

bool wait_until(const std::function<bool()>& condition, Clock::duration timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  while (!condition()) {
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

// Echoes every byte back on the connection it came from. Counts its reads, so a
// test can tell whether bytes arrived in fragments.
class EchoServer {
 public:
  EchoServer() : acceptor_(io_, tcp::endpoint(asio::ip::address_v4::loopback(), 0)) {
    port_ = acceptor_.local_endpoint().port();
    accept();
    thread_ = std::thread([this] { io_.run(); });
  }
  EchoServer(const EchoServer&) = delete;
  EchoServer& operator=(const EchoServer&) = delete;
  ~EchoServer() {
    io_.stop();
    thread_.join();
  }

  [[nodiscard]] std::uint16_t port() const { return port_; }
  [[nodiscard]] std::uint64_t reads() const { return reads_; }

 private:
  struct Connection : std::enable_shared_from_this<Connection> {
    Connection(tcp::socket connected, std::atomic<std::uint64_t>& read_count)
        : socket(std::move(connected)), reads(read_count) {}

    void echo() {
      socket.async_read_some(asio::buffer(buffer), [self = shared_from_this()](const error_code& ec, std::size_t n) {
        if (ec) return;  // the last reference goes, and the socket closes
        ++self->reads;
        asio::async_write(self->socket, asio::buffer(self->buffer.data(), n),
                          [self](const error_code& write_ec, std::size_t) {
                            if (!write_ec) self->echo();
                          });
      });
    }

    tcp::socket socket;
    std::atomic<std::uint64_t>& reads;
    std::array<std::uint8_t, 64 * 1024> buffer{};
  };

  void accept() {
    acceptor_.async_accept([this](const error_code& ec, tcp::socket socket) {
      if (ec) return;
      std::make_shared<Connection>(std::move(socket), reads_)->echo();
      accept();
    });
  }

  asio::io_context io_;
  tcp::acceptor acceptor_;
  std::uint16_t port_ = 0;
  std::atomic<std::uint64_t> reads_{0};
  std::thread thread_;
};

// Blocking calls that never block past a deadline: the socket is non-blocking and
// every wait is a poll() bounded by the time left.
class Client {
 public:
  Client() : socket_(io_) {}

  [[nodiscard]] bool connect(std::uint16_t port, Clock::duration timeout) {
    const Clock::time_point deadline = Clock::now() + timeout;
    socket_.open(tcp::v4());
    socket_.non_blocking(true);
    // Not socket_.connect(): asio waits for a non-blocking connect with no timeout.
    const tcp::endpoint target(asio::ip::address_v4::loopback(), port);
    if (::connect(socket_.native_handle(), target.data(), static_cast<socklen_t>(target.size())) == 0) return true;
    if (errno != EINPROGRESS || poll_for(POLLOUT, deadline) == 0) return false;
    int error = 0;
    socklen_t error_size = sizeof(error);
    return ::getsockopt(socket_.native_handle(), SOL_SOCKET, SO_ERROR, &error, &error_size) == 0 && error == 0;
  }

  // Sends `out` while reading what comes back (which keeps an echo from deadlocking
  // on full buffers), until `expected` bytes came or the deadline or an error ended it.
  Bytes exchange(const Bytes& out, std::size_t expected, Clock::duration timeout) {
    return transfer(out, expected, Clock::now() + timeout).received;
  }
  Bytes exchange(const Bytes& out, Clock::duration timeout) { return exchange(out, out.size(), timeout); }
  [[nodiscard]] bool send(const Bytes& out, Clock::duration timeout) {
    return transfer(out, 0, Clock::now() + timeout).sent == out.size();
  }
  Bytes receive(std::size_t expected, Clock::duration timeout) { return exchange({}, expected, timeout); }

  // Reads and drops bytes until the stream ends; returns the error that ended it,
  // or timed_out.
  error_code wait_for_close(Clock::duration timeout) {
    const Clock::time_point deadline = Clock::now() + timeout;
    std::array<std::uint8_t, 4096> buffer{};
    for (;;) {
      if (poll_for(POLLIN, deadline) == 0) return asio::error::timed_out;
      error_code ec;
      socket_.read_some(asio::buffer(buffer), ec);
      if (ec && ec != asio::error::would_block) return ec;
    }
  }

  void shutdown_send() { socket_.shutdown(tcp::socket::shutdown_send); }

 private:
  struct Transferred {
    std::size_t sent = 0;
    Bytes received;
  };

  Transferred transfer(const Bytes& out, std::size_t expected, Clock::time_point deadline) {
    Transferred done;
    std::array<std::uint8_t, 64 * 1024> buffer{};
    while (done.sent < out.size() || done.received.size() < expected) {
      const bool want_write = done.sent < out.size();
      const bool want_read = done.received.size() < expected;
      const short ready = poll_for(static_cast<short>((want_write ? POLLOUT : 0) | (want_read ? POLLIN : 0)), deadline);
      if (ready == 0) break;
      error_code ec;
      if (want_write && (ready & (POLLOUT | POLLERR | POLLHUP)) != 0) {
        done.sent += socket_.write_some(asio::buffer(out.data() + done.sent, out.size() - done.sent), ec);
        if (ec && ec != asio::error::would_block) break;
      }
      if (want_read && (ready & (POLLIN | POLLERR | POLLHUP)) != 0) {
        const std::size_t n = socket_.read_some(
            asio::buffer(buffer.data(), std::min(buffer.size(), expected - done.received.size())), ec);
        if (ec && ec != asio::error::would_block) break;
        done.received.insert(done.received.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
      }
    }
    return done;
  }

  // The events that are ready, or 0 once the deadline passed.
  short poll_for(short events, Clock::time_point deadline) {
    for (;;) {
      const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
      if (left <= 0ms) return 0;
      pollfd fd{socket_.native_handle(), events, 0};
      const int n = ::poll(&fd, 1, static_cast<int>(left.count()));
      if (n > 0) return fd.revents;
      if (n < 0 && errno != EINTR) return 0;
    }
  }

  asio::io_context io_;
  tcp::socket socket_;
};

class FaultProxyTest : public ::testing::Test {
 protected:
  std::unique_ptr<Client> connect_client() {
    auto client = std::make_unique<Client>();
    EXPECT_TRUE(client->connect(proxy_->port(), 2s));
    return client;
  }

  EchoServer echo_;
  std::unique_ptr<FaultProxy> proxy_ = std::make_unique<FaultProxy>(echo_.port());
};

TEST_F(FaultProxyTest, PassesALargePayloadUnchangedBothWays) {
  const Bytes payload = random_bytes(1 << 20, 1);
  auto client = connect_client();
  const Bytes echoed = client->exchange(payload, 5s);
  ASSERT_EQ(echoed.size(), payload.size());
  EXPECT_TRUE(echoed == payload) << "the echo differs from what was sent";
  EXPECT_EQ(proxy_->connections_accepted(), 1u);
  // The last write's handler may run just after the client has its bytes.
  EXPECT_TRUE(wait_until([&] { return proxy_->bytes_forwarded() == 2 * payload.size(); }, 2s))
      << proxy_->bytes_forwarded();
}

TEST_F(FaultProxyTest, CorruptionSpoilsOneByteOfWhatTheTargetSendsOnce) {
  proxy_->corrupt_from_target_at(70000);
  const Bytes payload = random_bytes(200000, 3);
  auto client = connect_client();
  const Bytes echoed = client->exchange(payload, 5s);
  ASSERT_EQ(echoed.size(), payload.size());
  std::vector<std::size_t> differ;
  for (std::size_t i = 0; i < payload.size(); ++i) {
    if (echoed[i] != payload[i]) differ.push_back(i);
  }
  ASSERT_EQ(differ.size(), 1u);
  EXPECT_EQ(differ.front(), 70000u);
  EXPECT_EQ(echoed[70000], payload[70000] ^ 0x10);
  EXPECT_EQ(proxy_->corruptions_done(), 1u);
  // Once: the next exchange passes unchanged.
  EXPECT_TRUE(client->exchange(payload, 5s) == payload);
}

TEST_F(FaultProxyTest, DelayAddsAtLeastTheBaseEachWay) {
  proxy_->set_delay(40ms, 0us);
  auto client = connect_client();
  const Bytes message = random_bytes(16, 2);
  const Clock::time_point start = Clock::now();
  EXPECT_EQ(client->exchange(message, 2s), message);
  EXPECT_GE(Clock::now() - start, 80ms);
}

TEST_F(FaultProxyTest, JitterNeverReordersBytes) {
  proxy_->set_delay(0us, 4ms);
  auto client = connect_client();
  // Many small writes spaced out, so the proxy reads them as separate chunks and
  // draws each its own delay.
  Bytes all;
  for (std::uint32_t i = 0; i < 200; ++i) {
    const Bytes piece = random_bytes(32, 100 + i);
    all.insert(all.end(), piece.begin(), piece.end());
    ASSERT_TRUE(client->send(piece, 2s));
    std::this_thread::sleep_for(100us);
  }
  EXPECT_TRUE(client->receive(all.size(), 5s) == all) << "bytes were lost or reordered";
  EXPECT_GT(echo_.reads(), 10u) << "the pieces were not forwarded as separate chunks";
}

TEST_F(FaultProxyTest, ByteAtATimeDeliversEverythingInOrder) {
  proxy_->set_byte_at_a_time(true);
  const Bytes payload = random_bytes(16 * 1024, 3);
  auto client = connect_client();
  const Bytes echoed = client->exchange(payload, 8s);
  ASSERT_EQ(echoed.size(), payload.size());
  EXPECT_TRUE(echoed == payload);
  // Single bytes a few microseconds apart: the server sees many small reads.
  EXPECT_GT(echo_.reads(), 100u);
}

TEST_F(FaultProxyTest, ByteIntervalDripsBytesOneByOne) {
  proxy_->set_byte_at_a_time(true);
  proxy_->set_byte_interval(2ms);
  const Bytes message = random_bytes(30, 4);
  auto client = connect_client();
  const Clock::time_point start = Clock::now();
  EXPECT_EQ(client->exchange(message, 3s), message);
  EXPECT_GE(Clock::now() - start, 29 * 2ms);
  // Bytes 2 ms apart arrive in separate reads unless the server falls far behind.
  EXPECT_GE(echo_.reads(), 15u);
}

TEST_F(FaultProxyTest, ResetAllAbortsEveryConnectionWithAReset) {
  const Bytes hello = {'h', 'e', 'l', 'l', 'o'};
  auto first = connect_client();
  auto second = connect_client();
  ASSERT_EQ(first->exchange(hello, 2s), hello);
  ASSERT_EQ(second->exchange(hello, 2s), hello);

  EXPECT_EQ(proxy_->reset_all(), 2u);
  EXPECT_EQ(proxy_->resets_done(), 2u);
  for (Client* client : {first.get(), second.get()}) {
    const error_code ec = client->wait_for_close(2s);
    // An RST, not a FIN: the client must see the connection reset, not an end of file.
    EXPECT_EQ(ec, asio::error::connection_reset) << ec.message();
  }

  // The proxy itself goes on.
  auto third = connect_client();
  EXPECT_EQ(third->exchange(hello, 2s), hello);
  EXPECT_EQ(proxy_->resets_done(), 2u);
}

TEST_F(FaultProxyTest, RefuseClosesNewConnections) {
  proxy_->set_refuse(true);
  auto refused = connect_client();
  const error_code ec = refused->wait_for_close(2s);
  EXPECT_NE(ec, asio::error::timed_out);
  EXPECT_EQ(proxy_->connections_accepted(), 1u);

  proxy_->set_refuse(false);
  const Bytes hello = {'h', 'i'};
  auto accepted = connect_client();
  EXPECT_EQ(accepted->exchange(hello, 2s), hello);
}

TEST_F(FaultProxyTest, HalfCloseIsPassedOn) {
  const Bytes message = {'b', 'y', 'e'};
  auto client = connect_client();
  ASSERT_EQ(client->exchange(message, 2s), message);
  client->shutdown_send();
  // The echo server sees EOF only if the proxy passed the half-close on; it then
  // closes, and that comes back the same way.
  EXPECT_EQ(client->wait_for_close(2s), asio::error::eof);
}

TEST(FaultProxy, UnreachableTargetClosesTheClient) {
  std::uint16_t closed_port = 0;
  {
    asio::io_context io;
    tcp::acceptor probe(io, tcp::endpoint(asio::ip::address_v4::loopback(), 0));
    closed_port = probe.local_endpoint().port();
  }
  FaultProxy proxy(closed_port);
  Client client;
  ASSERT_TRUE(client.connect(proxy.port(), 2s));
  EXPECT_NE(client.wait_for_close(2s), asio::error::timed_out);
}

TEST_F(FaultProxyTest, DestructorClosesConnectionsWithoutWaiting) {
  proxy_->set_delay(10s, 0us);
  auto client = connect_client();
  ASSERT_TRUE(client->send(random_bytes(1000, 5), 2s));
  ASSERT_TRUE(wait_until([&] { return proxy_->connections_accepted() == 1; }, 2s));

  const Clock::time_point start = Clock::now();
  proxy_.reset();
  EXPECT_LT(Clock::now() - start, 1s);
  EXPECT_NE(client->wait_for_close(2s), asio::error::timed_out);
}

}  // namespace
}  // namespace optique::testing
