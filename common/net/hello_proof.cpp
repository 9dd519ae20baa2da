#include "net/hello_proof.h"

#include <vector>

namespace optique::net {

Result<SessionKeys> check_hello(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                                const wire::Hello& hello, std::uint32_t protocol_version, const std::string& who,
                                const std::string& without_secret) {
  const std::string& mac = hello.nonce_mac();
  if (mac.empty()) return Error{"this master requires the installation's shared secret: " + without_secret};
  const std::string& peer_nonce = hello.node_nonce();
  if (peer_nonce.size() != kNonceBytes) {
    return Error{"the hello's " + who + " nonce has " + std::to_string(peer_nonce.size()) + " bytes, not " +
                 std::to_string(kNonceBytes)};
  }
  const auto peer_bytes = std::span(reinterpret_cast<const std::uint8_t*>(peer_nonce.data()), peer_nonce.size());
  std::vector<std::uint8_t> both(master_nonce.begin(), master_nonce.end());
  both.insert(both.end(), peer_bytes.begin(), peer_bytes.end());
  if (!verify_hello_mac(secret, both, hello.node_id(), protocol_version,
                        std::span(reinterpret_cast<const std::uint8_t*>(mac.data()), mac.size()))) {
    return Error{"authentication failed: the " + who + "'s secret does not match the master's"};
  }
  return derive_session_keys(secret, master_nonce, peer_bytes, hello.node_id(), protocol_version);
}

SessionKeys prove_hello(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                        std::span<const std::uint8_t> own_nonce, std::uint32_t protocol_version, wire::Hello& hello) {
  std::vector<std::uint8_t> both(master_nonce.begin(), master_nonce.end());
  both.insert(both.end(), own_nonce.begin(), own_nonce.end());
  const auto mac = hello_mac(secret, both, hello.node_id(), protocol_version);
  hello.set_nonce_mac(mac.data(), mac.size());
  hello.set_node_nonce(own_nonce.data(), own_nonce.size());
  return derive_session_keys(secret, master_nonce, own_nonce, hello.node_id(), protocol_version);
}

}  // namespace optique::net
