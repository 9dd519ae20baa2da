#include "net/connection.h"

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include <google/protobuf/arena.h>

#include "net/envelope.h"
#include "net/stamped_receive.h"

namespace optique::net {

std::shared_ptr<Connection> Connection::create(asio::ip::tcp::socket socket, std::uint32_t max_payload_bytes) {
  return std::shared_ptr<Connection>(new Connection(std::move(socket), max_payload_bytes));
}

Connection::Connection(asio::ip::tcp::socket socket, std::uint32_t max_payload_bytes)
    : socket_(std::move(socket)),
      liveness_timer_(socket_.get_executor()),
      deadline_timer_(socket_.get_executor()),
      reader_(max_payload_bytes),
      reader_max_(max_payload_bytes),
      last_receive_(std::chrono::steady_clock::now()) {
  boost::system::error_code ec;
  socket_.set_option(asio::ip::tcp::no_delay(true), ec);
  // Without stamps a message's time is when it is read: coarser, not wrong.
  (void)enable_receive_stamps(socket_.native_handle());
  const auto endpoint = socket_.remote_endpoint(ec);
  peer_ = ec ? std::string("unknown peer") : endpoint.address().to_string() + ":" + std::to_string(endpoint.port());
}

Connection::~Connection() = default;

void Connection::start(Handlers handlers) {
  handlers_ = std::move(handlers);
  // Not read here: a message must not reach its handler before start() returns.
  asio::post(socket_.get_executor(), [self = shared_from_this()] { self->read_available(); });
}

void Connection::send(wire::Envelope& message) {
  if (!open_ || closing_) return;
  message.set_protocol_version(message.protocol_version() != 0 ? message.protocol_version() : kProtocolVersion);
  message.set_sequence(next_send_sequence_++);
  if (sealer_) {
    std::vector<std::uint8_t> plain(message.ByteSizeLong());
    (void)message.SerializeWithCachedSizesToArray(plain.data());
    append_frame(outbox_, sealer_->seal(plain));
  } else {
    append_envelope(outbox_, message);
  }
  queued();
}

void Connection::send_serialized(std::span<const std::uint8_t> body) {
  if (!open_ || closing_) return;
  const std::vector<std::uint8_t> plain = with_header(body, kProtocolVersion, next_send_sequence_++);
  append_frame(outbox_, sealer_ ? sealer_->seal(plain) : plain);
  queued();
}

// After a message was queued: closes a peer that does not read, else writes.
void Connection::queued() {
  if (queued_bytes() > kMaxQueuedBytes) {
    // Closed from the event loop, not from inside send(): the caller may be
    // iterating over sessions, and on_closed may drop the last reference to one.
    closing_ = true;
    outbox_.clear();
    asio::post(socket_.get_executor(),
               [self = shared_from_this(), reason = "peer is not reading its messages (more than " +
                                                    std::to_string(kMaxQueuedBytes >> 20) +
                                                    " MiB queued)"] { self->finish(reason); });
    return;
  }
  if (in_flight_.empty()) write_more();
}

void Connection::write_more() {
  if (outbox_.empty() || !open_) return;
  in_flight_.swap(outbox_);
  asio::async_write(socket_, asio::buffer(in_flight_),
                    [self = shared_from_this()](const boost::system::error_code& ec, std::size_t) {
                      self->in_flight_.clear();
                      if (ec) {
                        if (ec != asio::error::operation_aborted) self->finish("write failed: " + ec.message());
                        return;
                      }
                      if (!self->outbox_.empty()) {
                        self->write_more();
                      } else if (self->closing_) {
                        self->finish(self->closing_reason_);
                      }
                    });
}

void Connection::hold_reading(bool held) {
  if (held == reading_held_) return;
  reading_held_ = held;
  if (held) return;
  asio::post(socket_.get_executor(), [self = shared_from_this()] {
    if (!self->open_ || self->reading_held_) return;
    self->handle_bytes(0, clock::monotonic_now());  // what the reader holds already
    if (self->open_ && !self->reading_held_ && !self->wait_armed_) self->read_available();
  });
}

// Readiness from Asio, the bytes from recvmsg(): Asio's reads drop the kernel's
// receive stamp. A message then costs what it cost with Asio's reads: one wait
// (Asio's async_wait re-arms epoll, which also reports bytes already there)
// and one read, where Asio tried a read that found nothing before each wait.
// A peek instead of async_wait costs one more read per message.
void Connection::wait_for_bytes() {
  if (wait_armed_) return;  // one wait at a time (a hold let go can meet a read already posted)
  wait_armed_ = true;
  socket_.async_wait(asio::ip::tcp::socket::wait_read,
                     [self = shared_from_this()](const boost::system::error_code& ec) {
                       self->wait_armed_ = false;
                       if (ec) {
                         if (ec != asio::error::operation_aborted) self->finish("read failed: " + ec.message());
                         return;
                       }
                       self->read_available();
                     });
}

void Connection::read_available() {
  // A peer that sends without pause must not keep the io thread to itself:
  // after this many full reads the rest waits behind what else is queued.
  constexpr int kReadsPerTurn = 16;
  for (int reads = 0; open_ && reads < kReadsPerTurn; ++reads) {
    if (reading_held_) return;  // hold_reading(false) reads on
    const StampedRead read = read_stamped(socket_.native_handle(), read_buffer_);
    switch (read.status) {
      case StampedRead::Status::data:
        handle_bytes(read.count, read.received);
        // Less than the buffer holds: the socket was empty. Bytes that came
        // since wake the wait all the same (re-arming epoll reports them).
        if (read.count < read_buffer_.size()) {
          if (open_) wait_for_bytes();
          return;
        }
        break;
      case StampedRead::Status::would_block:
        wait_for_bytes();
        return;
      case StampedRead::Status::closed:
        finish("peer closed the connection");
        return;
      case StampedRead::Status::failed:
        finish("read failed: " + boost::system::error_code(read.error, boost::system::system_category()).message());
        return;
    }
  }
  if (open_ && !reading_held_) {
    asio::post(socket_.get_executor(), [self = shared_from_this()] { self->read_available(); });
  }
}

void Connection::handle_bytes(std::size_t count, clock::Nanos received) {
  last_receive_ = std::chrono::steady_clock::now();
  if (closing_) return;  // draining: what the peer says no longer matters
  reader_.append({read_buffer_.data(), count});
  while (open_ && !closing_ && !reading_held_) {
    const DecodedFrame frame = reader_.next();
    if (frame.status == DecodeStatus::need_more) return;
    if (frame.status == DecodeStatus::bad) {
      close("bad frame: " + frame.error);
      return;
    }
    if (frame.status == DecodeStatus::oversized) {
      // Not read: the next message is the one after it in the seal's count and the sequence.
      if (opener_) opener_->skip();
      ++next_receive_sequence_;
      if (handlers_.on_oversized) handlers_.on_oversized(frame.length, reader_max_);
      continue;
    }
    std::span<const std::uint8_t> payload = frame.payload;
    std::vector<std::uint8_t> opened;
    if (opener_) {
      auto open = opener_->open(payload);
      const bool may_be_refusal = unsealed_refusal_allowed_;
      unsealed_refusal_allowed_ = false;
      if (!open) {
        if (may_be_refusal) {
          if (auto plain = parse_envelope(payload); plain && plain.value().has_refuse()) {
            wire::Refuse& refuse = *plain.value().mutable_refuse();
            refuse.set_reason(refuse.reason() + " (an unsealed answer: the master could not check this node's secret)");
            if (handlers_.on_message) handlers_.on_message(plain.value(), received);
            return;
          }
        }
        close(open.error());
        return;
      }
      opened = std::move(open).value();
      payload = opened;
    }
    if (!arena_block_) arena_block_ = std::make_unique<char[]>(kArenaBlockBytes);
    google::protobuf::ArenaOptions options;
    options.initial_block = arena_block_.get();
    options.initial_block_size = kArenaBlockBytes;
    google::protobuf::Arena arena(options);  // what it took beyond the block is freed with it
    auto* message = google::protobuf::Arena::CreateMessage<wire::Envelope>(&arena);
    if (auto parsed = parse_envelope_into(payload, *message); !parsed) {
      close("bad message: " + parsed.error());
      return;
    }
    if (message->sequence() != next_receive_sequence_) {
      close("message out of sequence (got " + std::to_string(message->sequence()) + ", expected " +
            std::to_string(next_receive_sequence_) + ")");
      return;
    }
    ++next_receive_sequence_;
    if (handlers_.on_message) handlers_.on_message(*message, received);
  }
}

void Connection::protect(const SessionKey& send, const SessionKey& receive, bool unsealed_refusal_first) {
  sealer_.emplace(send);
  opener_.emplace(receive);
  unsealed_refusal_allowed_ = unsealed_refusal_first;
}

void Connection::close(const std::string& reason) { finish(reason); }

void Connection::close_after_sending(const std::string& reason) {
  if (!open_ || closing_) return;
  closing_ = true;
  closing_reason_ = reason;
  if (in_flight_.empty() && outbox_.empty()) {
    finish(reason);
    return;
  }
  if (in_flight_.empty()) write_more();
  // A peer that does not read must not keep this side from closing.
  set_deadline(kDrainTimeout, reason + " (the peer did not take the last messages)");
}

void Connection::set_liveness_timeout(std::chrono::milliseconds timeout, std::string reason) {
  liveness_timeout_ = timeout;
  liveness_reason_ = std::move(reason);
  if (timeout.count() > 0) {
    arm_liveness();
  } else {
    liveness_timer_.cancel();
  }
}

// One timer for the whole connection rather than one reset per message: when it
// fires early (traffic came in meanwhile) it re-arms for the remaining time.
void Connection::arm_liveness() {
  liveness_timer_.expires_at(last_receive_ + liveness_timeout_);
  liveness_timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (ec || !self->open_ || self->liveness_timeout_.count() == 0) return;
    if (std::chrono::steady_clock::now() >= self->last_receive_ + self->liveness_timeout_) {
      self->finish(self->liveness_reason_);
    } else {
      self->arm_liveness();
    }
  });
}

// A generation number, not only cancel(): a timer that already fired has its
// handler queued, and cancel() no longer reaches it.
void Connection::set_deadline(std::chrono::milliseconds timeout, std::string reason) {
  const std::uint64_t generation = ++deadline_generation_;
  deadline_timer_.expires_after(timeout);
  deadline_timer_.async_wait(
      [self = shared_from_this(), generation, reason = std::move(reason)](const boost::system::error_code& ec) {
        if (!ec && self->open_ && generation == self->deadline_generation_) self->finish(reason);
      });
}

void Connection::cancel_deadline() {
  ++deadline_generation_;
  deadline_timer_.cancel();
}

void Connection::set_max_payload_bytes(std::uint32_t max_payload_bytes) {
  reader_.set_max_payload_bytes(max_payload_bytes);
  reader_max_ = max_payload_bytes;
}

void Connection::finish(const std::string& reason) {
  if (!open_) return;
  open_ = false;
  boost::system::error_code ignored;
  socket_.shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  socket_.close(ignored);
  liveness_timer_.cancel();
  deadline_timer_.cancel();
  // Handlers usually capture their owner; drop them so nothing keeps a cycle alive.
  Handlers handlers = std::move(handlers_);
  handlers_ = {};
  if (handlers.on_closed) handlers.on_closed(reason);
}

}  // namespace optique::net
