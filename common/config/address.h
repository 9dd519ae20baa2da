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

// The address as the kernel's inet_ntop writes it (IPv6 in its shortest, lower-
// case form; IPv4 mapped into IPv6 as plain IPv4), so that two spellings of one
// address compare equal; `text` unchanged if it is not an address.
[[nodiscard]] inline std::string canonical_address(const std::string& text) {
  char out[INET6_ADDRSTRLEN] = {};
  in_addr v4{};
  if (inet_pton(AF_INET, text.c_str(), &v4) == 1) return inet_ntop(AF_INET, &v4, out, sizeof out) ? out : text;
  in6_addr v6{};
  if (inet_pton(AF_INET6, text.c_str(), &v6) != 1) return text;
  if (IN6_IS_ADDR_V4MAPPED(&v6)) return inet_ntop(AF_INET, &v6.s6_addr[12], out, sizeof out) ? out : text;
  return inet_ntop(AF_INET6, &v6, out, sizeof out) ? out : text;
}

}  // namespace optique::config
