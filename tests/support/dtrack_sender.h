#pragma once
// A synthetic ART DTrack for tests: its ASCII output sent over UDP on loopback,
// from another host's address if asked (127.0.0.2 is another host than
// 127.0.0.1 to the master), and a free UDP port for the master to listen on.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>

namespace optique::testing {

// A UDP sender of DTrack's ASCII output.
class DTrackSender {
 public:
  // From `from` (a loopback address: 127.0.0.2 is another host than 127.0.0.1
  // to the master); none: the kernel's choice.
  explicit DTrackSender(int port, const char* from = nullptr) : socket_(::socket(AF_INET, SOCK_DGRAM, 0)) {
    if (from != nullptr) {
      sockaddr_in self{};
      self.sin_family = AF_INET;
      (void)::inet_pton(AF_INET, from, &self.sin_addr);
      (void)::bind(socket_, reinterpret_cast<const sockaddr*>(&self), sizeof self);
      int size = 4 << 20;  // a flood that is not held up by its own send buffer
      (void)::setsockopt(socket_, SOL_SOCKET, SO_SNDBUF, &size, sizeof size);
    }
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<std::uint16_t>(port));
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  }
  ~DTrackSender() { ::close(socket_); }
  DTrackSender(const DTrackSender&) = delete;
  DTrackSender& operator=(const DTrackSender&) = delete;
  void send(const std::string& text) const {
    (void)::sendto(socket_, text.data(), text.size(), 0, reinterpret_cast<const sockaddr*>(&to_), sizeof to_);
  }

 private:
  int socket_;
  sockaddr_in to_{};
};

// A free UDP port on loopback (bound and let go: the master takes it next).
inline int free_udp_port() {
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  (void)::bind(s, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  (void)::getsockname(s, reinterpret_cast<sockaddr*>(&address), &length);
  ::close(s);
  return ntohs(address.sin_port);
}

}  // namespace optique::testing
