#pragma once
// Shared-secret authentication for the master/node handshake, still free of
// sockets: loading the secret file, drawing the master's challenge nonce, and the
// node's answer, an HMAC-SHA256 that binds nonce, node id and protocol version.
// Kept apart from the connection code so every refusal and every bit of the
// encoding can be tested without a network.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "util/result.h"

namespace optique::net {

inline constexpr std::size_t kNonceBytes = 32;
inline constexpr std::size_t kHelloMacBytes = 32;  // HMAC-SHA256
inline constexpr std::size_t kMinSecretBytes = 16;
inline constexpr std::size_t kMaxSecretBytes = 4096;

// The key both sides hold. Deliberately without operator<< or any formatter:
// it must never end up in a log line.
struct Secret {
  std::vector<std::uint8_t> bytes;
};

// Reads the shared secret from `path`. Refuses (naming the path and what to do)
// a file that cannot be opened, is not a regular file, is readable or writable by
// other users (mode & 007), is larger than kMaxSecretBytes, or is shorter than
// kMinSecretBytes once trailing whitespace is stripped. Trailing whitespace
// ('\n', "\r\n", spaces, tabs) is stripped because echo and editors add it: two
// copies of one secret must not disagree over a newline.
[[nodiscard]] Result<Secret> load_secret_file(const std::string& path);

// `bytes` bytes from OpenSSL's CSPRNG, for the master's Challenge. Throws
// std::runtime_error when the generator fails: there is no safe fallback for a
// nonce, so the process is meant to stop (the exception reaches main).
[[nodiscard]] std::vector<std::uint8_t> random_nonce(std::size_t bytes = kNonceBytes);

// The node's answer to a Challenge: HMAC-SHA256(secret, message) where message is
//   "optique hello v1" | be32(nonce size) | nonce | be32(node id size) | node id
//   | be32(protocol_version).
// The lengths make the encoding unambiguous; binding node id and version keeps a
// mac from being relayed for another node or replayed across protocol versions.
// Throws std::invalid_argument for an empty secret (a default-constructed one:
// a mac under an empty key proves nothing) or a field too long for its length
// prefix, and std::runtime_error if OpenSSL fails: never a mac that was not
// computed.
[[nodiscard]] std::array<std::uint8_t, kHelloMacBytes> hello_mac(const Secret& secret,
                                                                 std::span<const std::uint8_t> nonce,
                                                                 std::string_view node_id,
                                                                 std::uint32_t protocol_version);

// The bearer token of the master's status server: HMAC-SHA256(secret,
// "optique status token v1") in lower-case hex, 64 characters. Derived, not the
// secret itself: the status server speaks plain HTTP, and a token seen on the
// way must not let a node in. Throws as hello_mac does.
[[nodiscard]] std::string status_token(const Secret& secret);

// The master's check of a Hello: recomputes hello_mac and compares in constant
// time. False for a mac of the wrong length and for an empty secret.
[[nodiscard]] bool verify_hello_mac(const Secret& secret, std::span<const std::uint8_t> nonce, std::string_view node_id,
                                    std::uint32_t protocol_version, std::span<const std::uint8_t> mac);

}  // namespace optique::net
