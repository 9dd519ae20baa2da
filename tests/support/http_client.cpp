#include "http_client.h"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <sstream>

namespace optique::testing {

HttpReply parse_reply(const std::string& raw) {
  HttpReply reply;
  const auto end_of_head = raw.find("\r\n\r\n");
  if (end_of_head == std::string::npos) {
    reply.error = "no whole reply head in " + std::to_string(raw.size()) + " bytes: " + raw.substr(0, 200);
    return reply;
  }
  std::istringstream head(raw.substr(0, end_of_head));
  std::string line;
  std::getline(head, line);
  std::istringstream status_line(line);
  std::string version;
  status_line >> version >> reply.status;
  if (version.rfind("HTTP/1.", 0) != 0 || reply.status == 0) {
    reply.error = "not an HTTP reply: " + line;
    return reply;
  }
  while (std::getline(head, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
    std::string value = line.substr(colon + 1);
    value.erase(0, value.find_first_not_of(' '));
    reply.headers[name] = value;
  }
  reply.body = raw.substr(end_of_head + 4);
  if (const auto length = reply.headers.find("content-length"); length != reply.headers.end()) {
    const std::size_t expected = std::stoul(length->second);
    if (reply.body.size() < expected) {
      reply.error = "body of " + std::to_string(reply.body.size()) + " bytes, " + length->second + " announced";
    }
    reply.body.resize(std::min(reply.body.size(), expected));
  }
  return reply;
}

std::string non_loopback_address() {
  ifaddrs* all = nullptr;
  if (getifaddrs(&all) != 0) return "";
  std::string found;
  for (const ifaddrs* i = all; i != nullptr && found.empty(); i = i->ifa_next) {
    if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET || (i->ifa_flags & IFF_UP) == 0 ||
        (i->ifa_flags & IFF_LOOPBACK) != 0) {
      continue;
    }
    char text[INET_ADDRSTRLEN] = {};
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
    if (inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text) != nullptr) found = text;
  }
  freeifaddrs(all);
  return found;
}

RawClient::RawClient(int port, const ClientOptions& options) {
  fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd_ >= 0 && options.receive_buffer > 0) {
    // Before connect(): the window the client offers is set then.
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &options.receive_buffer, sizeof options.receive_buffer);
  }
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (inet_pton(AF_INET, options.address.c_str(), &address.sin_addr) != 1) address.sin_addr.s_addr = INADDR_NONE;
  if (fd_ >= 0 && ::connect(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd_);
    fd_ = -1;
  }
}

RawClient::~RawClient() {
  if (fd_ >= 0) ::close(fd_);
}

bool RawClient::send(const std::string& bytes) {
  std::size_t sent = 0;
  while (fd_ >= 0 && sent < bytes.size()) {
    const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return fd_ >= 0;
}

long RawClient::read_once(std::chrono::milliseconds timeout) {
  if (fd_ < 0 || closed_) return 0;
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return -1;
  char buffer[65536];
  const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
  if (n <= 0) {
    closed_ = true;  // closed, or reset
    return 0;
  }
  received_.append(buffer, static_cast<std::size_t>(n));
  return n;
}

std::string RawClient::read_until_closed(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!closed_ && std::chrono::steady_clock::now() < until) {
    (void)read_once(std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
  }
  return received_;
}

bool RawClient::read_until(const std::string& needle, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (received_.find(needle) == std::string::npos) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
    if (left.count() <= 0 || read_once(left) <= 0) return received_.find(needle) != std::string::npos;
  }
  return true;
}

bool RawClient::discard_for(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!closed_ && std::chrono::steady_clock::now() < until) {
    (void)read_once(std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now()));
    received_.clear();
  }
  return !closed_;
}

bool RawClient::closed_within(std::chrono::milliseconds timeout) {
  (void)read_until_closed(timeout);
  return closed_;
}

HttpReply RawClient::read_reply(std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    HttpReply reply = parse_reply(received_);
    if (reply.error.empty()) {
      const auto head = received_.find("\r\n\r\n") + 4;
      received_.erase(0, head + reply.body.size());
      return reply;
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - std::chrono::steady_clock::now());
    if (left.count() <= 0 || read_once(left) <= 0) return reply;
  }
}

HttpReply http_request(int port, const std::string& method, const std::string& path, const std::string& token,
                       std::chrono::milliseconds timeout) {
  RawClient client(port);
  if (!client.connected()) return {0, {}, {}, "cannot connect to 127.0.0.1:" + std::to_string(port)};
  std::string request = method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n";
  if (!token.empty()) request += "Authorization: Bearer " + token + "\r\n";
  if (method == "POST") request += "Content-Length: 0\r\n";
  request += "\r\n";
  if (!client.send(request)) return {0, {}, {}, "cannot send the request"};
  return parse_reply(client.read_until_closed(timeout));
}

}  // namespace optique::testing
