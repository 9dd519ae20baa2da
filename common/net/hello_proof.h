#pragma once
// A Hello under the installation's shared secret, for a node (the node port)
// and for an application (master.api) alike: the peer's proof, and the
// master's check of it. The hello's nonce and MAC prove the peer holds the
// secret, and both sides derive the session's keys from it (net/session_seal.h).

#include <cstdint>
#include <span>
#include <string>

#include "net/auth.h"
#include "net/session_seal.h"
#include "optique/wire.pb.h"
#include "util/result.h"

namespace optique::net {

// The keys of the session whose `hello` (answering a Challenge with
// `master_nonce`) proves it holds `secret`; or why not, in words for the peer
// (`who`: "node" or "application"; `without_secret`: what a peer that sent no
// MAC should do).
[[nodiscard]] Result<SessionKeys> check_hello(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                                              const wire::Hello& hello, std::uint32_t protocol_version,
                                              const std::string& who, const std::string& without_secret);

// The peer's side: proves in `hello` (its node_id already set) that it holds
// `secret`, answering a Challenge with `master_nonce` with its own fresh
// `own_nonce` (kNonceBytes each); the session's keys. Throws as hello_mac does.
[[nodiscard]] SessionKeys prove_hello(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                                      std::span<const std::uint8_t> own_nonce, std::uint32_t protocol_version,
                                      wire::Hello& hello);

}  // namespace optique::net
