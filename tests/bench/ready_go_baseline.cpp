#include "ready_go_baseline.h"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>

#include "clock/clock.h"

namespace optique::bench {
namespace {

void no_delay(int fd) {
  const int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

[[noreturn]] void client(std::uint16_t port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(port);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) _exit(1);
  no_delay(fd);
  char byte = 0;
  while (read(fd, &byte, 1) == 1) {
    if (write(fd, &byte, 1) != 1) break;
  }
  _exit(0);
}

}  // namespace

std::vector<double> ready_go_rounds(std::size_t clients, std::size_t rounds, double rate_hz) {
  const int listener = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || listen(listener, 64) != 0) {
    throw std::runtime_error("baseline: cannot listen");
  }
  socklen_t length = sizeof address;
  getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length);
  const std::uint16_t port = ntohs(address.sin_port);

  std::vector<pid_t> children;
  for (std::size_t i = 0; i < clients; ++i) {
    const pid_t pid = fork();
    if (pid == 0) {
      close(listener);
      client(port);
    }
    children.push_back(pid);
  }
  std::vector<pollfd> fds;
  for (std::size_t i = 0; i < clients; ++i) {
    const int fd = accept(listener, nullptr, nullptr);
    if (fd < 0) throw std::runtime_error("baseline: accept failed");
    no_delay(fd);
    fds.push_back({fd, POLLIN, 0});
  }
  close(listener);

  std::vector<double> times;
  const auto period = static_cast<clock::Nanos>(1e9 / rate_hz);
  clock::Nanos next = clock::monotonic_now();
  for (std::size_t round = 0; round < rounds; ++round) {
    clock::sleep_until_monotonic(next, 0);
    const clock::Nanos start = clock::monotonic_now();
    char go = 'g';
    for (const auto& p : fds) {
      if (write(p.fd, &go, 1) != 1) throw std::runtime_error("baseline: write failed");
    }
    std::size_t waiting = clients;
    std::vector<bool> done(clients, false);
    while (waiting > 0) {
      for (auto& p : fds) p.revents = 0;
      poll(fds.data(), fds.size(), 1000);
      for (std::size_t i = 0; i < clients; ++i) {
        if (!done[i] && (fds[i].revents & POLLIN)) {
          char ready = 0;
          if (read(fds[i].fd, &ready, 1) != 1) throw std::runtime_error("baseline: client died");
          done[i] = true;
          --waiting;
        }
      }
    }
    times.push_back(static_cast<double>(clock::monotonic_now() - start) / 1e3);
    next += period;
  }
  for (const auto& p : fds) close(p.fd);
  for (pid_t pid : children) {
    int status = 0;
    waitpid(pid, &status, 0);
  }
  return times;
}

}  // namespace optique::bench
