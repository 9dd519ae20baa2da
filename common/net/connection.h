#pragma once
// One TCP connection carrying Envelopes: asynchronous reads through a FrameReader
// (each message with the kernel's receive time),
// coalesced asynchronous writes, and deadlines owned by the session (a liveness
// timeout and an optional one-shot deadline). Never a blocking read. Used on one
// io_context thread; not thread-safe.

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clock/clock.h"
#include "net/framing.h"
#include "net/session_seal.h"
#include "optique/wire.pb.h"

namespace optique::net {

namespace asio = boost::asio;

class Connection : public std::enable_shared_from_this<Connection> {
 public:
  struct Handlers {
    // `received`: when the kernel received the message's last bytes (monotonic
    // clock; see stamped_receive.h), the time to use for anything measured on it.
    std::function<void(wire::Envelope& message, clock::Nanos received)> on_message;
    // Called once, when the connection is gone for any reason.
    std::function<void(const std::string& reason)> on_closed;
    // With skip_oversized(): a message over the maximum was passed over
    // (`bytes` long); the connection goes on.
    std::function<void(std::uint32_t bytes, std::uint32_t max_bytes)> on_oversized;
  };

  static std::shared_ptr<Connection> create(asio::ip::tcp::socket socket, std::uint32_t max_payload_bytes);

  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;
  ~Connection();

  void start(Handlers handlers);

  // Stamps protocol version and sequence number and queues the message.
  void send(wire::Envelope& message);
  // The same for a message already serialized without either (with_header):
  // one serialization for every peer it goes to.
  void send_serialized(std::span<const std::uint8_t> body);

  // Closes now; queued messages are dropped.
  void close(const std::string& reason);
  // Sends what is queued, then closes (a Refuse or a Goodbye must arrive).
  void close_after_sending(const std::string& reason);

  // Closes with `reason` when nothing arrives for `timeout` (0 turns it off).
  void set_liveness_timeout(std::chrono::milliseconds timeout, std::string reason);
  // Closes with `reason` at `timeout` from now unless cancel_deadline() is called.
  void set_deadline(std::chrono::milliseconds timeout, std::string reason);
  void cancel_deadline();
  // The largest frame accepted from now on (small before a peer has identified itself).
  void set_max_payload_bytes(std::uint32_t max_payload_bytes);
  // A message over that size is passed over and told to on_oversized (the
  // peer may be told and go on), instead of closing the connection.
  void skip_oversized() { reader_.set_skip_oversized(true); }
  // Held, nothing more is read or handed on: bytes wait in the kernel and the
  // reader. Let go, what waited is handed on and reading goes on. (The master
  // holds the applications' sessions while a barrier round is under way.)
  void hold_reading(bool held);
  // From now on every message sent is sealed with `send` and every message
  // received must open with `receive` (net/session_seal.h); one that does not
  // closes the connection. `unsealed_refusal_first`: the first message may
  // instead be a plain Refuse (a master that could not check this node's
  // secret cannot seal its answer), handed on marked as unsealed.
  void protect(const SessionKey& send, const SessionKey& receive, bool unsealed_refusal_first);

  [[nodiscard]] bool is_open() const { return open_; }
  [[nodiscard]] const std::string& peer() const { return peer_; }
  [[nodiscard]] std::size_t queued_bytes() const { return outbox_.size() + in_flight_.size(); }

  // A peer that does not read its messages is dropped past this much backlog.
  static constexpr std::size_t kMaxQueuedBytes = 64u << 20;
  // How long close_after_sending() waits for the peer to take what is queued.
  static constexpr std::chrono::milliseconds kDrainTimeout{2000};
  static constexpr std::size_t kArenaBlockBytes = 256 * 1024;

 private:
  Connection(asio::ip::tcp::socket socket, std::uint32_t max_payload_bytes);

  void wait_for_bytes();
  void read_available();
  void handle_bytes(std::size_t count, clock::Nanos received);
  void queued();
  void write_more();
  void arm_liveness();
  void finish(const std::string& reason);

  asio::ip::tcp::socket socket_;
  asio::steady_timer liveness_timer_;
  asio::steady_timer deadline_timer_;
  FrameReader reader_;
  std::uint32_t reader_max_;  // its maximum, for on_oversized
  Handlers handlers_;
  std::string peer_;
  std::array<std::uint8_t, 64 * 1024> read_buffer_{};
  // Each message is parsed on an arena that starts in this block, reused:
  // a frame's change of a thousand instances is thousands of small messages,
  // and was a quarter of a node's time in malloc and free. Allocated with the
  // first message.
  std::unique_ptr<char[]> arena_block_;
  std::vector<std::uint8_t> outbox_;
  std::vector<std::uint8_t> in_flight_;
  std::optional<Sealer> sealer_;
  std::optional<Opener> opener_;
  bool unsealed_refusal_allowed_ = false;  // the next message may be a plain Refuse
  bool reading_held_ = false;
  bool wait_armed_ = false;  // an async_wait for bytes is outstanding
  std::uint64_t next_send_sequence_ = 1;
  std::uint64_t next_receive_sequence_ = 1;
  std::uint64_t deadline_generation_ = 0;
  std::chrono::milliseconds liveness_timeout_{0};
  std::string liveness_reason_;
  std::chrono::steady_clock::time_point last_receive_;
  std::string closing_reason_;
  bool open_ = true;
  bool closing_ = false;
};

}  // namespace optique::net
