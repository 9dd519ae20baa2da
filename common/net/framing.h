#pragma once
// Framing on the wire: a 4-byte big-endian payload length, then the payload (one
// serialized Envelope). Pure functions over bytes, no sockets: a decoder says
// good, bad or need-more, and checks the length against a maximum before anything
// is allocated for the payload.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace optique::net {

inline constexpr std::size_t kFrameHeaderBytes = 4;
inline constexpr std::uint32_t kDefaultMaxPayloadBytes = 16u << 20;

// oversized: a frame longer than the maximum, which a FrameReader that skips
// such frames passes over (its bytes are dropped as they come, never held).
enum class DecodeStatus { good, bad, need_more, oversized };

struct DecodedFrame {
  DecodeStatus status = DecodeStatus::need_more;
  std::span<const std::uint8_t> payload;  // good: view into the input
  std::size_t consumed = 0;               // good: header + payload bytes
  std::string error;                      // bad, oversized: why
  std::uint32_t length = 0;               // bad (over the maximum), oversized: the payload's length
};

// Looks at the start of `bytes` for one whole frame.
[[nodiscard]] DecodedFrame decode_frame(std::span<const std::uint8_t> bytes, std::uint32_t max_payload_bytes);

// Writes the 4-byte big-endian length header at `at`.
void write_frame_header(std::uint8_t* at, std::uint32_t payload_length);

// Appends header + payload to `out`.
void append_frame(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> payload);

// Accumulates bytes as they arrive (in any fragmentation) and hands out frames.
// After a bad frame it stays bad: the stream cannot be resynchronized.
class FrameReader {
 public:
  explicit FrameReader(std::uint32_t max_payload_bytes = kDefaultMaxPayloadBytes)
      : max_payload_bytes_(max_payload_bytes) {}

  void append(std::span<const std::uint8_t> bytes);

  // The next whole frame, if any. A good frame's payload stays valid until the
  // next call to append() or next().
  [[nodiscard]] DecodedFrame next();

  [[nodiscard]] std::size_t buffered_bytes() const { return buffer_.size() - read_pos_; }
  void set_max_payload_bytes(std::uint32_t max_payload_bytes) { max_payload_bytes_ = max_payload_bytes; }
  // A frame over the maximum is passed over (next() says so once, as
  // oversized, then drops its payload as it comes) instead of ending the
  // stream: for a peer that may be told its message was too large.
  void set_skip_oversized(bool skip) { skip_oversized_ = skip; }

 private:
  std::uint32_t max_payload_bytes_;
  bool skip_oversized_ = false;
  std::uint64_t skipping_ = 0;  // payload bytes of an oversized frame still to drop
  std::vector<std::uint8_t> buffer_;
  std::size_t read_pos_ = 0;
  std::string failure_;
};

}  // namespace optique::net
