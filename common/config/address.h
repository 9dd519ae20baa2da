#pragma once
// Whether a config's `listen` is an address to bind (IPv4 or IPv6, numeric):
// host names are not resolved where a bind would have to guess.

#include <arpa/inet.h>

#include <string>

namespace optique::config {

[[nodiscard]] inline bool is_ip_address(const std::string& text) {
  in6_addr buffer{};
  return inet_pton(AF_INET, text.c_str(), &buffer) == 1 || inet_pton(AF_INET6, text.c_str(), &buffer) == 1;
}

}  // namespace optique::config
