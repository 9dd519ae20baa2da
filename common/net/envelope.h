#pragma once
// One Envelope per frame: serialization and parsing, still free of sockets.

#include <cstdint>
#include <span>
#include <vector>

#include <string>

#include "optique/wire.pb.h"
#include "util/result.h"

namespace optique::net {

// Bumped whenever a message changes meaning; master and node must agree exactly.
// 5: the welcome says how many lights the scene has; 6: the scene's files travel
// from the master to nodes that lack them; 7: a node that is behind is told to
// skip frames, and says how long its warm-up frame took; 8: the state carries
// the live scene's instances (and the hash covers them), and applications speak
// the scene session on master.api.
inline constexpr std::uint32_t kProtocolVersion = 8;

// Serializes `envelope` and appends it as one frame to `out`.
void append_envelope(std::vector<std::uint8_t>& out, const wire::Envelope& envelope);

// The payload of `body` (serialized, its protocol version and sequence unset)
// sent with this version and sequence: the body's bytes, then the two fields'.
// Protobuf reads fields that follow as set on the message, so a body shared by
// several peers is serialized once and each peer's sequence added after it.
[[nodiscard]] std::vector<std::uint8_t> with_header(std::span<const std::uint8_t> body, std::uint32_t version,
                                                    std::uint64_t sequence);

// Parses one frame's payload. Fails on bytes that are not an Envelope or an
// Envelope without a body; the protocol version is left for the handshake to judge.
[[nodiscard]] Result<wire::Envelope> parse_envelope(std::span<const std::uint8_t> payload);
// The same into `envelope` (one on an arena, say), which it clears first.
[[nodiscard]] Result<void> parse_envelope_into(std::span<const std::uint8_t> payload, wire::Envelope& envelope);

// "frame_begin", "hello", ...: for log lines.
[[nodiscard]] const char* body_name(const wire::Envelope& envelope);

// A Refuse: its reason, and whether trying again later may get in (sent plain,
// with the protocol version, as a peer that is refused may not share keys).
[[nodiscard]] wire::Envelope refusal(const std::string& reason, bool retriable);

}  // namespace optique::net
