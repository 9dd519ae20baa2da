#pragma once
// Every message after the handshake, sealed: AES-256-GCM with a key per
// direction, derived by HKDF-SHA256 from the shared secret and both sides'
// fresh nonces, and a nonce that is the frame's count in its direction. So a
// peer that does not hold the secret can neither read nor write a message, and
// a message replayed, dropped, reordered or moved to another session fails to
// open. The master proves it holds the secret with its first sealed message
// (the node's nonce is fresh: no earlier session's messages open under the new
// keys). OpenSSL does the cryptography; this file only says how it is used.
// No sockets: net::Connection seals and opens each frame's payload.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "net/auth.h"
#include "util/result.h"

namespace optique::net {

inline constexpr std::size_t kSessionKeyBytes = 32;  // AES-256
inline constexpr std::size_t kSealTagBytes = 16;     // GCM's tag

using SessionKey = std::array<std::uint8_t, kSessionKeyBytes>;

// The two keys of a session. Deliberately without operator<<: never logged.
struct SessionKeys {
  SessionKey to_node{};
  SessionKey to_master{};
};

// HKDF-SHA256(secret; salt = master nonce | node nonce; info = "optique session
// v1" | node id | protocol version) → to_node | to_master. Throws as hello_mac
// does (an empty secret, OpenSSL failing): never keys that were not derived.
[[nodiscard]] SessionKeys derive_session_keys(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                                              std::span<const std::uint8_t> node_nonce, std::string_view node_id,
                                              std::uint32_t protocol_version);

// OpenSSL's cipher context, keyed once: each frame then sets only its nonce
// (fetching the cipher and expanding the key per frame cost ~20 µs a message).
struct CipherContext;
struct CipherContextFree {
  void operator()(CipherContext* context) const;
};
using CipherContextPtr = std::unique_ptr<CipherContext, CipherContextFree>;

// One direction of a session: seals the frames it sends, or opens the frames it
// receives, counting them; the count is the GCM nonce and never repeats (2^64).
class Sealer {
 public:
  // Throws std::runtime_error when OpenSSL cannot set the key up.
  explicit Sealer(const SessionKey& key);
  // `payload` sealed: the ciphertext, then the tag. Throws std::runtime_error
  // when OpenSSL fails (never a frame sent unsealed).
  [[nodiscard]] std::vector<std::uint8_t> seal(std::span<const std::uint8_t> payload);

 private:
  CipherContextPtr context_;
  std::uint64_t count_ = 0;
};

class Opener {
 public:
  // Throws std::runtime_error when OpenSSL cannot set the key up.
  explicit Opener(const SessionKey& key);
  // The payload of the next frame in order, or why it cannot be one: too short
  // for a tag, or it does not open (forged, changed, replayed, reordered, or a
  // frame missing before it). After a failure the session is over.
  [[nodiscard]] Result<std::vector<std::uint8_t>> open(std::span<const std::uint8_t> sealed);
  // The next frame in order was not read (too large to take): the one after
  // it opens with the count after its.
  void skip() { ++count_; }

 private:
  CipherContextPtr context_;
  std::uint64_t count_ = 0;
};

}  // namespace optique::net
