#include "util/sha256.h"

#include <openssl/evp.h>

#include <array>
#include <cassert>

namespace optique::util {

struct Sha256::Context {
  EVP_MD_CTX* md = EVP_MD_CTX_new();
  Context() {
    const int ok = md != nullptr ? EVP_DigestInit_ex(md, EVP_sha256(), nullptr) : 0;
    assert(ok == 1);
    (void)ok;
  }
  ~Context() { EVP_MD_CTX_free(md); }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
};

Sha256::Sha256() : context_(std::make_unique<Context>()) {}
Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

void Sha256::update(std::string_view bytes) {
  const int ok = EVP_DigestUpdate(context_->md, bytes.data(), bytes.size());
  assert(ok == 1);
  (void)ok;
}

std::string Sha256::finish() {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  int ok = EVP_DigestFinal_ex(context_->md, digest.data(), &length);
  assert(ok == 1 && length == kSha256Bytes);
  ok = EVP_DigestInit_ex(context_->md, EVP_sha256(), nullptr);
  assert(ok == 1);
  (void)ok;
  return {reinterpret_cast<const char*>(digest.data()), length};
}

std::string sha256_raw(std::string_view bytes) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  const int ok = EVP_Digest(bytes.data(), bytes.size(), digest.data(), &length, EVP_sha256(), nullptr);
  assert(ok == 1 && length == kSha256Bytes);
  (void)ok;
  return {reinterpret_cast<const char*>(digest.data()), length};
}

std::string to_hex(std::string_view bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * bytes.size());
  for (const char c : bytes) {
    const auto byte = static_cast<unsigned char>(c);
    hex.push_back(kHex[byte >> 4]);
    hex.push_back(kHex[byte & 0xF]);
  }
  return hex;
}

std::string sha256_hex(std::string_view bytes) { return to_hex(sha256_raw(bytes)); }

}  // namespace optique::util
