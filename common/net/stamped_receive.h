#pragma once
// One non-blocking read from a socket together with the time the kernel received
// the bytes (SO_TIMESTAMPNS), on the monotonic clock.
//
// Why: the clock estimator pairs a ping's send and receive times. Stamped when the
// io thread gets round to reading, a leg's time includes the wake-up of that
// thread (10–40 µs on a busy machine, more on one leg than the other), which the
// estimator cannot tell from clock offset. The kernel's stamp is taken when the
// packet arrives, before any thread is scheduled. The kernel starts stamping a
// moment after the first socket of the system asks for it: a connection's first
// messages may come unstamped (and carry the time of the read).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "clock/clock.h"

namespace optique::net {

// Asks the kernel to stamp what the socket receives. False where it cannot (the
// reads then fall back to the time of the read).
[[nodiscard]] bool enable_receive_stamps(int fd);

struct StampedRead {
  enum class Status { data, would_block, closed, failed };
  Status status = Status::failed;
  std::size_t count = 0;  // bytes read, for data
  int error = 0;          // errno, for failed
  // When the kernel received the last of these bytes (monotonic), or the time
  // of the read where the kernel gave no stamp.
  clock::Nanos received = 0;
};

[[nodiscard]] StampedRead read_stamped(int fd, std::span<std::uint8_t> buffer);

// One datagram (UDP) and who sent it; an empty datagram is data of 0 bytes.
struct StampedDatagram {
  StampedRead read;
  std::string sender;  // its address as inet_ntop writes it (an IPv4-mapped one as IPv4); empty if unknown
};
[[nodiscard]] StampedDatagram read_datagram_stamped(int fd, std::span<std::uint8_t> buffer);

}  // namespace optique::net
