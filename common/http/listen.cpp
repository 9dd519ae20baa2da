#include "http/listen.h"

#include <boost/asio/ip/address.hpp>
#include <boost/asio/socket_base.hpp>

namespace optique::http {

Result<std::uint16_t> listen_on(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address,
                                std::uint16_t port) {
  namespace asio = boost::asio;
  boost::system::error_code ec;
  const auto ip = asio::ip::make_address(address, ec);
  if (ec) return Error{"'" + address + "' is not an address"};
  const asio::ip::tcp::endpoint endpoint(ip, port);
  acceptor.open(endpoint.protocol(), ec);
  if (!ec) acceptor.set_option(asio::ip::tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor.bind(endpoint, ec);
  if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return Error{"cannot listen on " + address + ":" + std::to_string(port) + ": " + ec.message()};
  return acceptor.local_endpoint().port();
}

}  // namespace optique::http
