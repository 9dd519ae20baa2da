#pragma once

#include <string>
#include <string_view>

namespace optique::util {

// SHA-256 of `bytes` as 64 lowercase hex digits (OpenSSL libcrypto).
[[nodiscard]] std::string sha256_hex(std::string_view bytes);

}  // namespace optique::util
