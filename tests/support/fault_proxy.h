#pragma once
// A fault-injecting TCP proxy for integration tests: this machine has no netem, so
// delay, jitter, fragmentation and connection resets are made here, in-process. A
// test points a node at port() instead of at the master.
//
// The proxy runs its own io_context on its own thread; every setter may be called
// from any other thread at any time and applies to bytes read from then on.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace optique::testing {

class FaultProxy {
 public:
  // Listens on 127.0.0.1 at an ephemeral port and forwards each accepted connection
  // to 127.0.0.1:target_port. Throws if it cannot listen.
  explicit FaultProxy(std::uint16_t target_port);
  FaultProxy(const FaultProxy&) = delete;
  FaultProxy& operator=(const FaultProxy&) = delete;
  ~FaultProxy();  // closes every connection; never waits on a peer

  [[nodiscard]] std::uint16_t port() const;

  // Each chunk read from either side is held base + uniform [0, jitter] before it is
  // forwarded; chunks still leave in the order they came, in each direction.
  void set_delay(std::chrono::microseconds base, std::chrono::microseconds jitter);
  // Forward one byte per write, to exercise fragmentation and slow-drip peers.
  void set_byte_at_a_time(bool enabled);
  // Pause between two single-byte writes (only in byte-at-a-time mode).
  void set_byte_interval(std::chrono::microseconds interval);
  // Close newly accepted connections at once, without connecting to the target.
  void set_refuse(bool enabled);
  // Flips a bit of the byte at `offset` of what the target sends on a connection
  // (counted from its first byte), once: on the first connection whose stream
  // gets that far. A spoilt byte that TCP's checksum let through.
  void corrupt_from_target_at(std::uint64_t offset);
  // Bytes spoilt so far.
  [[nodiscard]] std::uint64_t corruptions_done() const;
  // Aborts every open connection pair with a TCP RST on both sides; returns how many
  // it aborted once they are. Must not be called from the proxy's own thread.
  std::size_t reset_all();

  // Every connection accepted, refused ones included.
  [[nodiscard]] std::uint64_t connections_accepted() const;
  // Connection pairs aborted by reset_all().
  [[nodiscard]] std::uint64_t resets_done() const;
  // Bytes written to either side, both directions together.
  [[nodiscard]] std::uint64_t bytes_forwarded() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace optique::testing
