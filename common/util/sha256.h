#pragma once

#include <memory>
#include <string>
#include <string_view>

namespace optique::util {

inline constexpr std::size_t kSha256Bytes = 32;

// SHA-256 of `bytes` as 64 lowercase hex digits (OpenSSL libcrypto).
[[nodiscard]] std::string sha256_hex(std::string_view bytes);
// The same as 32 raw bytes.
[[nodiscard]] std::string sha256_raw(std::string_view bytes);
// 32 raw bytes (any bytes) as lowercase hex.
[[nodiscard]] std::string to_hex(std::string_view bytes);

// A SHA-256 over bytes given piece by piece (a file read in chunks).
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;

  void update(std::string_view bytes);
  // The digest of everything given (32 raw bytes); then it starts over.
  [[nodiscard]] std::string finish();

 private:
  struct Context;
  std::unique_ptr<Context> context_;
};

}  // namespace optique::util
