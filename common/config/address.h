#pragma once
// Whether a config's `listen` is an address to bind (IPv4 or IPv6, numeric):
// host names are not resolved where a bind would have to guess. And whether it
// is reached from this machine only.

#include <arpa/inet.h>

#include <string>

namespace optique::config {

[[nodiscard]] inline bool is_ip_address(const std::string& text) {
  in6_addr buffer{};
  return inet_pton(AF_INET, text.c_str(), &buffer) == 1 || inet_pton(AF_INET6, text.c_str(), &buffer) == 1;
}

// A loopback address (127.0.0.0/8, ::1, or IPv4 loopback mapped into IPv6):
// only this machine reaches it.
[[nodiscard]] inline bool is_loopback_address(const std::string& text) {
  in_addr v4{};
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, text.c_str(), &v6) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

}  // namespace optique::config
