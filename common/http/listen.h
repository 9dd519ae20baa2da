#pragma once
// A listening TCP socket on `address`:`port` (0: any free port): what the
// status server and the master's other ports (master/app/tcp_listener.h) open
// the same way. The port bound, or why not.

#include <boost/asio/ip/tcp.hpp>

#include <cstdint>
#include <string>

#include "util/result.h"

namespace optique::http {

[[nodiscard]] Result<std::uint16_t> listen_on(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address,
                                              std::uint16_t port);

}  // namespace optique::http
