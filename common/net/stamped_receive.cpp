#include "net/stamped_receive.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <ctime>

namespace optique::net {

bool enable_receive_stamps(int fd) {
  const int on = 1;
  return ::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on) == 0;
}

namespace {

clock::Nanos nanos(const timespec& t) {
  return static_cast<clock::Nanos>(t.tv_sec) * clock::kNanosPerSecond + t.tv_nsec;
}

// The kernel stamps with CLOCK_REALTIME. Its distance to CLOCK_MONOTONIC, read
// now, maps the stamp; it only moves when the wall clock is stepped, which a
// stamp microseconds old does not straddle but for a rare instant.
clock::Nanos monotonic_from_realtime(clock::Nanos realtime) {
  timespec wall{};
  ::clock_gettime(CLOCK_REALTIME, &wall);
  const clock::Nanos monotonic = clock::monotonic_now();
  const clock::Nanos mapped = realtime - (nanos(wall) - monotonic);
  // A stamp from the future or from long ago is not one to trust (a wall clock
  // step in between): the read's own time is then the better guess.
  if (mapped > monotonic || monotonic - mapped > clock::kNanosPerSecond) return monotonic;
  return mapped;
}

// One recvmsg; `from` (may be null) gets the sender's address.
StampedRead receive(int fd, std::span<std::uint8_t> buffer, sockaddr_storage* from, bool datagram) {
  StampedRead read;
  iovec io{buffer.data(), buffer.size()};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
  msghdr message{};
  message.msg_name = from;
  message.msg_namelen = from != nullptr ? sizeof(sockaddr_storage) : 0;
  message.msg_iov = &io;
  message.msg_iovlen = 1;
  message.msg_control = control;
  message.msg_controllen = sizeof control;
  ssize_t count = 0;
  do {
    count = ::recvmsg(fd, &message, MSG_DONTWAIT);
  } while (count < 0 && errno == EINTR);
  if (count < 0) {
    read.error = errno;
    read.status =
        (errno == EAGAIN || errno == EWOULDBLOCK) ? StampedRead::Status::would_block : StampedRead::Status::failed;
    return read;
  }
  if (count == 0 && !datagram) {
    read.status = StampedRead::Status::closed;
    return read;
  }
  read.status = StampedRead::Status::data;
  read.count = static_cast<std::size_t>(count);
  bool stamped = false;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS && c->cmsg_len >= CMSG_LEN(sizeof(timespec))) {
      timespec stamp{};
      std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
      read.received = monotonic_from_realtime(nanos(stamp));
      stamped = true;
    }
  }
  if (!stamped) read.received = clock::monotonic_now();
  return read;
}

std::string address_text(const sockaddr_storage& from) {
  char text[INET6_ADDRSTRLEN] = {};
  if (from.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(from);
    ::inet_ntop(AF_INET, &v4.sin_addr, text, sizeof text);
  } else if (from.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(from);
    if (IN6_IS_ADDR_V4MAPPED(&v6.sin6_addr)) {
      ::inet_ntop(AF_INET, &v6.sin6_addr.s6_addr[12], text, sizeof text);
    } else {
      ::inet_ntop(AF_INET6, &v6.sin6_addr, text, sizeof text);
    }
  }
  return text;
}

}  // namespace

StampedRead read_stamped(int fd, std::span<std::uint8_t> buffer) { return receive(fd, buffer, nullptr, false); }

StampedDatagram read_datagram_stamped(int fd, std::span<std::uint8_t> buffer) {
  sockaddr_storage from{};
  StampedDatagram datagram;
  datagram.read = receive(fd, buffer, &from, true);
  if (datagram.read.status == StampedRead::Status::data) datagram.sender = address_text(from);
  return datagram;
}

}  // namespace optique::net
