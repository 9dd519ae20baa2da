#pragma once
// Who may open one more connection to the status server. Its connections are
// taken before anyone is authenticated, so without more than a total a few
// clients that re-open slow connections as they are closed hold every one, and
// the operator is locked out. So: at most `per_address` from one address (an
// IPv6 /64 counts as one: a single host may hold all of it), and
// `loopback_reserved` of the total only for peers on this machine: the others
// together hold at most the rest.
//
// Loopback is not held to `per_address`: whoever is on this machine can take
// the master's resources in plainer ways, local tools (a load test's hundred
// pollers, a reverse proxy in front of the page) are many clients on one
// address, and the reserved slots are for them. A reverse proxy on this
// machine does make its remote clients loopback ones: it should limit them.

#include <boost/asio/ip/address.hpp>

#include <cstddef>
#include <map>
#include <string>

namespace optique::http {

enum class Admission { admitted, busy, too_many_from_address };

class ConnectionBudget {
 public:
  // `loopback_reserved` is at most half of `max_connections`.
  ConnectionBudget(std::size_t max_connections, std::size_t per_address, std::size_t loopback_reserved);

  // Counts a connection from `peer` until release() when it is admitted.
  [[nodiscard]] Admission admit(const boost::asio::ip::address& peer);
  void release(const boost::asio::ip::address& peer);
  [[nodiscard]] std::size_t open() const { return open_; }

 private:
  std::size_t max_connections_;
  std::size_t per_address_;
  std::size_t loopback_reserved_;
  std::size_t open_ = 0;
  std::size_t remote_open_ = 0;                    // of them, not from loopback
  std::map<std::string, std::size_t> by_address_;  // not loopback
};

}  // namespace optique::http
