#include "net/session_seal.h"

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/kdf.h>

#include <climits>
#include <memory>
#include <stdexcept>
#include <string>

#include "net/openssl_error.h"
#include "util/big_endian.h"

namespace optique::net {
namespace {

constexpr std::string_view kSessionLabel = "optique session v1";
constexpr std::size_t kIvBytes = 12;

struct ContextFree {
  void operator()(EVP_PKEY_CTX* c) const { EVP_PKEY_CTX_free(c); }
};

// 4 zero bytes, then the count big-endian: unique per key as long as the count
// does not wrap, which 2^64 frames do not.
std::array<std::uint8_t, kIvBytes> iv_for(std::uint64_t count) {
  std::array<std::uint8_t, kIvBytes> iv{};
  for (int i = 0; i < 8; ++i)
    iv[kIvBytes - 1 - static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(count >> (8 * i));
  return iv;
}

}  // namespace

SessionKeys derive_session_keys(const Secret& secret, std::span<const std::uint8_t> master_nonce,
                                std::span<const std::uint8_t> node_nonce, std::string_view node_id,
                                std::uint32_t protocol_version) {
  if (secret.bytes.empty()) throw std::invalid_argument("derive_session_keys: empty secret");
  std::vector<std::uint8_t> salt(master_nonce.begin(), master_nonce.end());
  salt.insert(salt.end(), node_nonce.begin(), node_nonce.end());
  std::vector<std::uint8_t> info(kSessionLabel.begin(), kSessionLabel.end());
  util::append_be32(info, static_cast<std::uint32_t>(node_id.size()));
  info.insert(info.end(), node_id.begin(), node_id.end());
  util::append_be32(info, protocol_version);
  if (secret.bytes.size() > INT_MAX || salt.size() > INT_MAX || info.size() > INT_MAX) {
    throw std::invalid_argument("derive_session_keys: input too long");
  }
  std::unique_ptr<EVP_PKEY_CTX, ContextFree> context(EVP_PKEY_CTX_new_id(EVP_PKEY_HKDF, nullptr));
  std::array<std::uint8_t, 2 * kSessionKeyBytes> out{};
  std::size_t length = out.size();
  if (!context || EVP_PKEY_derive_init(context.get()) != 1 ||
      EVP_PKEY_CTX_set_hkdf_md(context.get(), EVP_sha256()) != 1 ||
      EVP_PKEY_CTX_set1_hkdf_salt(context.get(), salt.data(), static_cast<int>(salt.size())) != 1 ||
      EVP_PKEY_CTX_set1_hkdf_key(context.get(), secret.bytes.data(), static_cast<int>(secret.bytes.size())) != 1 ||
      EVP_PKEY_CTX_add1_hkdf_info(context.get(), info.data(), static_cast<int>(info.size())) != 1 ||
      EVP_PKEY_derive(context.get(), out.data(), &length) != 1 || length != out.size()) {
    throw std::runtime_error("HKDF-SHA256 failed: " + openssl_error());
  }
  SessionKeys keys;
  std::copy(out.begin(), out.begin() + kSessionKeyBytes, keys.to_node.begin());
  std::copy(out.begin() + kSessionKeyBytes, out.end(), keys.to_master.begin());
  return keys;
}

// The OpenSSL context behind the opaque name the header uses.
struct CipherContext {
  EVP_CIPHER_CTX* context = nullptr;
};

void CipherContextFree::operator()(CipherContext* c) const {
  if (c != nullptr) EVP_CIPHER_CTX_free(c->context);
  delete c;
}

namespace {

CipherContextPtr keyed_context(const SessionKey& key, bool encrypt) {
  CipherContextPtr c(new CipherContext{EVP_CIPHER_CTX_new()});
  const bool keyed = c->context != nullptr &&
                     (encrypt ? EVP_EncryptInit_ex(c->context, EVP_aes_256_gcm(), nullptr, key.data(), nullptr)
                              : EVP_DecryptInit_ex(c->context, EVP_aes_256_gcm(), nullptr, key.data(), nullptr)) == 1;
  if (!keyed) throw std::runtime_error("AES-256-GCM set-up failed: " + openssl_error());
  return c;
}

}  // namespace

Sealer::Sealer(const SessionKey& key) : context_(keyed_context(key, true)) {}

Opener::Opener(const SessionKey& key) : context_(keyed_context(key, false)) {}

std::vector<std::uint8_t> Sealer::seal(std::span<const std::uint8_t> payload) {
  if (payload.size() > INT_MAX) throw std::invalid_argument("Sealer::seal: payload too long");
  const auto iv = iv_for(count_);
  EVP_CIPHER_CTX* context = context_->context;
  std::vector<std::uint8_t> sealed(payload.size() + kSealTagBytes);
  int written = 0;
  int final_written = 0;
  if (EVP_EncryptInit_ex(context, nullptr, nullptr, nullptr, iv.data()) != 1 ||
      EVP_EncryptUpdate(context, sealed.data(), &written, payload.data(), static_cast<int>(payload.size())) != 1 ||
      EVP_EncryptFinal_ex(context, sealed.data() + written, &final_written) != 1 ||
      static_cast<std::size_t>(written + final_written) != payload.size() ||
      EVP_CIPHER_CTX_ctrl(context, EVP_CTRL_GCM_GET_TAG, static_cast<int>(kSealTagBytes),
                          sealed.data() + payload.size()) != 1) {
    throw std::runtime_error("AES-256-GCM failed: " + openssl_error());
  }
  ++count_;
  return sealed;
}

Result<std::vector<std::uint8_t>> Opener::open(std::span<const std::uint8_t> sealed) {
  if (sealed.size() < kSealTagBytes) {
    return Error{"a sealed message of " + std::to_string(sealed.size()) + " bytes has no room for its tag"};
  }
  if (sealed.size() > INT_MAX) return Error{"a sealed message too long to open"};
  const std::size_t length = sealed.size() - kSealTagBytes;
  const auto iv = iv_for(count_);
  EVP_CIPHER_CTX* context = context_->context;
  std::vector<std::uint8_t> payload(length);
  int written = 0;
  int final_written = 0;
  // The tag is only read by the library; its API takes a non-const pointer.
  std::array<std::uint8_t, kSealTagBytes> tag{};
  std::copy(sealed.begin() + static_cast<std::ptrdiff_t>(length), sealed.end(), tag.begin());
  if (EVP_DecryptInit_ex(context, nullptr, nullptr, nullptr, iv.data()) != 1 ||
      EVP_DecryptUpdate(context, payload.data(), &written, sealed.data(), static_cast<int>(length)) != 1 ||
      EVP_CIPHER_CTX_ctrl(context, EVP_CTRL_GCM_SET_TAG, static_cast<int>(kSealTagBytes), tag.data()) != 1) {
    return Error{"cannot open a sealed message: " + openssl_error()};
  }
  if (EVP_DecryptFinal_ex(context, payload.data() + written, &final_written) != 1) {
    ERR_clear_error();
    return Error{"message " + std::to_string(count_) +
                 " of the session failed authentication (forged, changed, replayed, reordered, or sealed with "
                 "another secret)"};
  }
  ++count_;
  return payload;
}

}  // namespace optique::net
