#pragma once
// Which nodes the current frame still waits for. Pure bookkeeping, no sockets or
// timers: the master feeds it events and asks whether the frame may swap.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace optique::master {

class Barrier {
 public:
  // Starts waiting for `expected` (node slots) on `frame`.
  void begin(std::uint64_t frame, std::vector<std::size_t> expected);
  // A node reported ready; returns whether it was waited for.
  bool ready(std::size_t slot);
  // A node is gone (disconnected, or taken out after a timeout): stop waiting for it.
  void leave(std::size_t slot);
  void end() { active_ = false; }

  [[nodiscard]] bool active() const { return active_; }
  [[nodiscard]] std::uint64_t frame() const { return frame_; }
  [[nodiscard]] bool complete() const { return active_ && waiting_.empty(); }
  [[nodiscard]] const std::vector<std::size_t>& waiting_for() const { return waiting_; }

 private:
  std::uint64_t frame_ = 0;
  std::vector<std::size_t> waiting_;
  bool active_ = false;
};

}  // namespace optique::master
