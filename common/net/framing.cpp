#include "net/framing.h"

#include <algorithm>

namespace optique::net {

DecodedFrame decode_frame(std::span<const std::uint8_t> bytes, std::uint32_t max_payload_bytes) {
  DecodedFrame frame;
  if (bytes.size() < kFrameHeaderBytes) return frame;
  const std::uint32_t length = (std::uint32_t{bytes[0]} << 24) | (std::uint32_t{bytes[1]} << 16) |
                               (std::uint32_t{bytes[2]} << 8) | std::uint32_t{bytes[3]};
  if (length == 0) {
    frame.status = DecodeStatus::bad;
    frame.error = "empty frame (length 0)";
    return frame;
  }
  if (length > max_payload_bytes) {
    frame.status = DecodeStatus::bad;
    frame.length = length;
    frame.error =
        "frame of " + std::to_string(length) + " bytes exceeds the maximum of " + std::to_string(max_payload_bytes);
    return frame;
  }
  if (bytes.size() - kFrameHeaderBytes < length) return frame;
  frame.status = DecodeStatus::good;
  frame.payload = bytes.subspan(kFrameHeaderBytes, length);
  frame.consumed = kFrameHeaderBytes + length;
  return frame;
}

void write_frame_header(std::uint8_t* at, std::uint32_t payload_length) {
  at[0] = static_cast<std::uint8_t>(payload_length >> 24);
  at[1] = static_cast<std::uint8_t>(payload_length >> 16);
  at[2] = static_cast<std::uint8_t>(payload_length >> 8);
  at[3] = static_cast<std::uint8_t>(payload_length);
}

void append_frame(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> payload) {
  const std::size_t start = out.size();
  out.resize(start + kFrameHeaderBytes);
  write_frame_header(out.data() + start, static_cast<std::uint32_t>(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
}

void FrameReader::append(std::span<const std::uint8_t> bytes) {
  if (!failure_.empty()) return;
  // Drop what was already handed out before growing, so the buffer stays bounded
  // by one frame plus one read.
  if (read_pos_ > 0) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(read_pos_));
    read_pos_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

DecodedFrame FrameReader::next() {
  if (!failure_.empty()) {
    DecodedFrame bad;
    bad.status = DecodeStatus::bad;
    bad.error = failure_;
    return bad;
  }
  if (skipping_ > 0) {
    const std::uint64_t dropped = std::min<std::uint64_t>(skipping_, buffer_.size() - read_pos_);
    read_pos_ += static_cast<std::size_t>(dropped);
    skipping_ -= dropped;
    if (skipping_ > 0) return DecodedFrame{};
  }
  const std::span<const std::uint8_t> pending(buffer_.data() + read_pos_, buffer_.size() - read_pos_);
  DecodedFrame frame = decode_frame(pending, max_payload_bytes_);
  if (frame.status == DecodeStatus::bad && frame.length > 0 && skip_oversized_) {
    read_pos_ += kFrameHeaderBytes;
    skipping_ = frame.length;
    frame.status = DecodeStatus::oversized;
    return frame;
  }
  if (frame.status == DecodeStatus::good) {
    read_pos_ += frame.consumed;
  } else if (frame.status == DecodeStatus::bad) {
    failure_ = frame.error;
    buffer_.clear();
    read_pos_ = 0;
  }
  return frame;
}

}  // namespace optique::net
