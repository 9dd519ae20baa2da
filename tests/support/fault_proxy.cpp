#include "fault_proxy.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/write.hpp>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <deque>
#include <exception>
#include <future>
#include <mutex>
#include <random>
#include <thread>
#include <utility>
#include <vector>

namespace optique::testing {
namespace {

namespace asio = boost::asio;
using asio::ip::tcp;
using boost::system::error_code;
using Clock = std::chrono::steady_clock;

// Past this many bytes waiting in one direction the proxy stops reading from the
// sender, so a slow fault pushes back on it the way a real link's window would.
constexpr std::size_t kMaxQueuedBytes = std::size_t{1} << 20;
constexpr std::size_t kReadBufferBytes = 64 * 1024;

struct Faults {
  std::chrono::microseconds base_delay{0};
  std::chrono::microseconds jitter{0};
  bool byte_at_a_time = false;
  std::chrono::microseconds byte_interval{0};
};

// What the sessions share with the proxy. It outlives the io_context, so it
// outlives every session.
struct ProxyState {
  tcp::endpoint target;
  std::atomic<bool> refuse{false};
  std::atomic<std::uint64_t> connections_accepted{0};
  std::atomic<std::uint64_t> resets_done{0};
  std::atomic<std::uint64_t> bytes_forwarded{0};
  std::atomic<std::int64_t> corrupt_at{-1};  // in the target's stream; -1: none pending
  std::atomic<std::uint64_t> corruptions_done{0};

  std::mutex faults_mutex;
  Faults faults;            // guarded by faults_mutex: the test thread changes it
  std::mt19937_64 rng{42};  // io thread only; fixed seed: the same draws every run

  Faults current_faults() {
    const std::lock_guard lock(faults_mutex);
    return faults;
  }

  Clock::duration draw_delay() {
    const Faults faults_now = current_faults();
    std::uniform_int_distribution<std::int64_t> jitter(0, std::max<std::int64_t>(0, faults_now.jitter.count()));
    return faults_now.base_delay + std::chrono::microseconds(jitter(rng));
  }
};

// One accepted connection and its connection to the target. Every pending handler
// holds a shared_ptr to it, so it lives exactly as long as some operation does.
class Session : public std::enable_shared_from_this<Session> {
 public:
  Session(ProxyState& state, tcp::socket client)
      : state_(state),
        client_(std::move(client)),
        server_(client_.get_executor()),
        upstream_(client_, server_),
        downstream_(server_, client_) {}

  void start() {
    server_.async_connect(state_.target, [self = shared_from_this()](const error_code& ec) {
      if (self->closed_) return;
      if (ec) {
        self->close(Ending::kGraceful);
        return;
      }
      // Nagle would merge the very fragments byte-at-a-time mode means to make.
      error_code ignored;
      self->client_.set_option(tcp::no_delay(true), ignored);
      self->server_.set_option(tcp::no_delay(true), ignored);
      self->read(self->upstream_);
      self->read(self->downstream_);
    });
  }

  // Returns whether the pair was still open, i.e. whether this was a reset.
  bool abort() {
    if (closed_) return false;
    close(Ending::kReset);
    return true;
  }

 private:
  struct Chunk {
    std::vector<std::uint8_t> bytes;
    std::size_t sent = 0;
    Clock::time_point due;
  };

  // Bytes flowing from one socket to the other. The queue is strictly FIFO, so a
  // chunk drawn a shorter delay than the one before it waits for it: jitter never
  // reorders bytes.
  struct Direction {
    Direction(tcp::socket& from_socket, tcp::socket& to_socket)
        : from(from_socket), to(to_socket), timer(to_socket.get_executor()), read_buffer(kReadBufferBytes) {}

    tcp::socket& from;
    tcp::socket& to;
    asio::steady_timer timer;
    std::vector<std::uint8_t> read_buffer;
    std::deque<Chunk> queue;
    std::size_t queued_bytes = 0;
    Clock::time_point next_write_not_before{};
    bool reading = false;
    bool writing = false;
    bool sender_done = false;
    bool eof_passed_on = false;
    std::uint64_t position = 0;  // bytes read from `from` so far
  };

  enum class Ending { kGraceful, kReset };

  void read(Direction& direction) {
    direction.reading = true;
    direction.from.async_read_some(asio::buffer(direction.read_buffer),
                                   [self = shared_from_this(), &direction](const error_code& ec, std::size_t length) {
                                     self->on_read(direction, ec, length);
                                   });
  }

  void on_read(Direction& direction, const error_code& ec, std::size_t length) {
    direction.reading = false;
    if (closed_) return;
    if (ec == asio::error::eof) {
      direction.sender_done = true;
      if (!direction.writing) write_next(direction);
      return;
    }
    if (ec) {
      // A peer's reset reaches the other peer as a reset too.
      close(Ending::kReset);
      return;
    }
    const auto first = direction.read_buffer.begin();
    if (&direction == &downstream_) {
      std::int64_t at = state_.corrupt_at.load();
      const auto offset = static_cast<std::uint64_t>(at);
      if (at >= 0 && offset >= direction.position && offset < direction.position + length &&
          state_.corrupt_at.compare_exchange_strong(at, -1)) {
        direction.read_buffer[offset - direction.position] ^= 0x10;
        ++state_.corruptions_done;
      }
    }
    direction.position += length;
    direction.queue.push_back(
        {{first, first + static_cast<std::ptrdiff_t>(length)}, 0, Clock::now() + state_.draw_delay()});
    direction.queued_bytes += length;
    if (!direction.writing) write_next(direction);
    if (direction.queued_bytes < kMaxQueuedBytes) read(direction);
  }

  void write_next(Direction& direction) {
    if (closed_) return;
    if (direction.queue.empty()) {
      direction.writing = false;
      if (direction.sender_done) pass_on_eof(direction);
      return;
    }
    direction.writing = true;
    Chunk& chunk = direction.queue.front();
    const Clock::time_point not_before = std::max(chunk.due, direction.next_write_not_before);
    if (Clock::now() < not_before) {
      direction.timer.expires_at(not_before);
      direction.timer.async_wait([self = shared_from_this(), &direction](const error_code& ec) {
        if (!ec) self->write_next(direction);
      });
      return;
    }
    const Faults faults = state_.current_faults();
    const std::size_t length = faults.byte_at_a_time ? 1 : chunk.bytes.size() - chunk.sent;
    const Clock::duration pause = faults.byte_at_a_time ? faults.byte_interval : Clock::duration::zero();
    asio::async_write(direction.to, asio::buffer(chunk.bytes.data() + chunk.sent, length),
                      [self = shared_from_this(), &direction, pause](const error_code& ec, std::size_t written) {
                        self->on_written(direction, ec, written, pause);
                      });
  }

  void on_written(Direction& direction, const error_code& ec, std::size_t written, Clock::duration pause) {
    if (closed_) return;
    if (ec) {
      close(Ending::kReset);
      return;
    }
    state_.bytes_forwarded += written;
    direction.queued_bytes -= written;
    Chunk& chunk = direction.queue.front();
    chunk.sent += written;
    if (chunk.sent == chunk.bytes.size()) direction.queue.pop_front();
    direction.next_write_not_before = Clock::now() + pause;
    if (!direction.reading && !direction.sender_done && direction.queued_bytes < kMaxQueuedBytes) read(direction);
    write_next(direction);
  }

  // The sender half-closed and everything it sent is delivered: half-close the
  // receiver too, so protocols that read to EOF still work through the proxy.
  void pass_on_eof(Direction& direction) {
    if (direction.eof_passed_on) return;
    direction.eof_passed_on = true;
    error_code ignored;
    direction.to.shutdown(tcp::socket::shutdown_send, ignored);
    if (upstream_.eof_passed_on && downstream_.eof_passed_on) close(Ending::kGraceful);
  }

  void close(Ending ending) {
    closed_ = true;
    for (tcp::socket* socket : {&client_, &server_}) {
      error_code ignored;
      // Linger on with a zero timeout makes close() send RST instead of FIN.
      if (ending == Ending::kReset) socket->set_option(tcp::socket::linger(true, 0), ignored);
      socket->close(ignored);
    }
    upstream_.timer.cancel();
    downstream_.timer.cancel();
  }

  ProxyState& state_;
  tcp::socket client_;
  tcp::socket server_;
  Direction upstream_;    // client to target
  Direction downstream_;  // target to client
  bool closed_ = false;
};

}  // namespace

class FaultProxy::Impl {
 public:
  explicit Impl(std::uint16_t target_port)
      : acceptor_(io_, tcp::endpoint(asio::ip::address_v4::loopback(), 0)), accept_retry_timer_(io_) {
    state_.target = tcp::endpoint(asio::ip::address_v4::loopback(), target_port);
    port_ = acceptor_.local_endpoint().port();
    accept();
    thread_ = std::thread([this] { run(); });
  }

  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // Stopping drops the pending handlers unrun; destroying io_ then destroys them,
  // and with them the last references to every session, whose sockets close. No
  // step waits on a peer.
  ~Impl() {
    io_.stop();
    thread_.join();
  }

  std::uint16_t port() const { return port_; }
  ProxyState& state() { return state_; }

  std::size_t reset_all() {
    std::promise<std::size_t> done;
    std::future<std::size_t> aborted = done.get_future();
    asio::post(io_, [this, &done] {
      std::size_t count = 0;
      for (const std::weak_ptr<Session>& weak : sessions_) {
        if (const std::shared_ptr<Session> session = weak.lock(); session && session->abort()) ++count;
      }
      sessions_.clear();
      state_.resets_done += count;
      done.set_value(count);
    });
    return aborted.get();
  }

 private:
  void run() {
    // A handler that throws must not take the proxy (or the test process) down.
    for (;;) {
      try {
        io_.run();
        return;
      } catch (const std::exception& e) {
        std::fprintf(stderr, "FaultProxy: %s\n", e.what());
      }
    }
  }

  void accept() {
    acceptor_.async_accept([this](const error_code& ec, tcp::socket client) {
      if (ec == asio::error::operation_aborted) return;
      if (ec) {
        // Out of descriptors, say: retry a little later rather than spin.
        accept_retry_timer_.expires_after(std::chrono::milliseconds(10));
        accept_retry_timer_.async_wait([this](const error_code& wait_ec) {
          if (!wait_ec) accept();
        });
        return;
      }
      ++state_.connections_accepted;
      if (state_.refuse) {
        error_code ignored;
        client.close(ignored);
      } else {
        start_session(std::move(client));
      }
      accept();
    });
  }

  void start_session(tcp::socket client) {
    std::erase_if(sessions_, [](const std::weak_ptr<Session>& weak) { return weak.expired(); });
    auto session = std::make_shared<Session>(state_, std::move(client));
    sessions_.push_back(session);
    session->start();
  }

  ProxyState state_;  // declared first: sessions destroyed with io_ still refer to it
  asio::io_context io_;
  tcp::acceptor acceptor_;
  asio::steady_timer accept_retry_timer_;
  std::vector<std::weak_ptr<Session>> sessions_;  // io thread only
  std::uint16_t port_ = 0;
  std::thread thread_;
};

FaultProxy::FaultProxy(std::uint16_t target_port) : impl_(std::make_unique<Impl>(target_port)) {}

FaultProxy::~FaultProxy() = default;

std::uint16_t FaultProxy::port() const { return impl_->port(); }

void FaultProxy::set_delay(std::chrono::microseconds base, std::chrono::microseconds jitter) {
  ProxyState& state = impl_->state();
  const std::lock_guard lock(state.faults_mutex);
  state.faults.base_delay = base;
  state.faults.jitter = jitter;
}

void FaultProxy::set_byte_at_a_time(bool enabled) {
  ProxyState& state = impl_->state();
  const std::lock_guard lock(state.faults_mutex);
  state.faults.byte_at_a_time = enabled;
}

void FaultProxy::set_byte_interval(std::chrono::microseconds interval) {
  ProxyState& state = impl_->state();
  const std::lock_guard lock(state.faults_mutex);
  state.faults.byte_interval = interval;
}

void FaultProxy::set_refuse(bool enabled) { impl_->state().refuse = enabled; }

std::size_t FaultProxy::reset_all() { return impl_->reset_all(); }

std::uint64_t FaultProxy::connections_accepted() const { return impl_->state().connections_accepted; }

std::uint64_t FaultProxy::resets_done() const { return impl_->state().resets_done; }

std::uint64_t FaultProxy::bytes_forwarded() const { return impl_->state().bytes_forwarded; }

void FaultProxy::corrupt_from_target_at(std::uint64_t offset) {
  impl_->state().corrupt_at = static_cast<std::int64_t>(offset);
}

std::uint64_t FaultProxy::corruptions_done() const { return impl_->state().corruptions_done; }

}  // namespace optique::testing
