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

enum class DecodeStatus { good, bad, need_more };

struct DecodedFrame {
  DecodeStatus status = DecodeStatus::need_more;
  std::span<const std::uint8_t> payload;  // good: view into the input
  std::size_t consumed = 0;               // good: header + payload bytes
  std::string error;                      // bad: why
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

 private:
  std::uint32_t max_payload_bytes_;
  std::vector<std::uint8_t> buffer_;
  std::size_t read_pos_ = 0;
  std::string failure_;
};

}  // namespace optique::net
