#pragma once
// How long a node takes to draw a frame, from what it reported: its warm-up
// frame, then its last few frames. The barrier waits for a node that is slow
// but steady as long as it usually takes, and takes out one that stalled.

#include <array>
#include <cstddef>
#include <optional>

#include "clock/clock.h"
#include "master/run_recorder.h"

namespace optique::master {

class RenderPace {
 public:
  static constexpr std::size_t kKept = 8;

  // A frame (or the warm-up) took `render` by the node's word, peer input:
  // clamped to 0 … kLongestRender (run_recorder.h), as a report bounds it.
  // `round` is how long the master waited for it, from sending its FrameBegin
  // to reading its answer: the draw, both trips, and on a busy machine the
  // waits for a core on either side. The barrier waits for the longer.
  void add(clock::Nanos render, clock::Nanos round);
  void add(clock::Nanos render) { add(render, render); }
  // Reading a captured frame back takes `capture` more (the node measured it
  // on its warm-up frame), peer input: clamped as add() clamps.
  void set_capture(clock::Nanos capture);
  // The median of the times kept; none before the first.
  [[nodiscard]] std::optional<clock::Nanos> typical() const;
  // How long the barrier waits for this node: `frame_timeout`, or twice the
  // slowest of the rounds kept when that is longer (a node that takes 300 ms a
  // frame, or a key frame every fourth, is slow, not stalled; one that takes
  // 1 s after 300 ms each is stalled), but never more than `longest` (a node
  // reporting absurd times does not hold the others up for long). A
  // `captured` frame is read back too: twice the slowest and the read-back.
  [[nodiscard]] clock::Nanos allowance(clock::Nanos frame_timeout, clock::Nanos longest, bool captured = false) const;

 private:
  std::array<clock::Nanos, kKept> times_{};   // as the node drew them: what typical() says
  std::array<clock::Nanos, kKept> rounds_{};  // as the master waited for them: what allowance() allows
  std::size_t count_ = 0;                     // all added, of which the last kKept are kept
  clock::Nanos capture_ = 0;
};

}  // namespace optique::master
