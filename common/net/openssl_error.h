#pragma once
// The text of OpenSSL's last error, for the messages of net's cryptography.

#include <string>

namespace optique::net {

[[nodiscard]] std::string openssl_error();

}  // namespace optique::net
