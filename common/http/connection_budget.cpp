#include "http/connection_budget.h"

#include <algorithm>

namespace optique::http {
namespace {

namespace ip = boost::asio::ip;

// IPv4 written through IPv6 (::ffff:a.b.c.d) is IPv4.
ip::address unmapped(const ip::address& address) {
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    return ip::make_address_v4(ip::v4_mapped, address.to_v6());
  }
  return address;
}

bool is_loopback(const ip::address& address) { return unmapped(address).is_loopback(); }

// The address, or its /64 for IPv6.
std::string group_of(const ip::address& address) {
  const ip::address plain = unmapped(address);
  if (plain.is_v4()) return plain.to_string();
  ip::address_v6::bytes_type bytes = plain.to_v6().to_bytes();
  std::fill(bytes.begin() + 8, bytes.end(), 0);
  return ip::address_v6(bytes).to_string() + "/64";
}

}  // namespace

ConnectionBudget::ConnectionBudget(std::size_t max_connections, std::size_t per_address, std::size_t loopback_reserved)
    : max_connections_(max_connections),
      per_address_(per_address),
      loopback_reserved_(std::min(loopback_reserved, max_connections / 2)) {}

Admission ConnectionBudget::admit(const ip::address& peer) {
  if (open_ >= max_connections_) return Admission::busy;
  if (is_loopback(peer)) {
    ++open_;
    return Admission::admitted;
  }
  if (remote_open_ >= max_connections_ - loopback_reserved_) return Admission::busy;
  const std::string group = group_of(peer);
  const auto found = by_address_.find(group);
  if (per_address_ == 0 || (found != by_address_.end() && found->second >= per_address_)) {
    return Admission::too_many_from_address;
  }
  ++by_address_[group];
  ++open_;
  ++remote_open_;
  return Admission::admitted;
}

void ConnectionBudget::release(const ip::address& peer) {
  if (open_ > 0) --open_;
  if (is_loopback(peer)) return;
  if (remote_open_ > 0) --remote_open_;
  const auto found = by_address_.find(group_of(peer));
  if (found == by_address_.end()) return;
  if (--found->second == 0) by_address_.erase(found);
}

}  // namespace optique::http
