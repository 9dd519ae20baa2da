#include "master/render_pace.h"

#include <algorithm>
#include <vector>

namespace optique::master {

void RenderPace::add(clock::Nanos render, clock::Nanos round) {
  times_[count_ % kKept] = std::clamp<clock::Nanos>(render, 0, kLongestRender);
  rounds_[count_ % kKept] = std::max(times_[count_ % kKept], std::clamp<clock::Nanos>(round, 0, kLongestRender));
  ++count_;
}

void RenderPace::set_capture(clock::Nanos capture) { capture_ = std::clamp<clock::Nanos>(capture, 0, kLongestRender); }

std::optional<clock::Nanos> RenderPace::typical() const {
  const std::size_t kept = std::min(count_, kKept);
  if (kept == 0) return std::nullopt;
  std::vector<clock::Nanos> sorted(times_.begin(), times_.begin() + static_cast<std::ptrdiff_t>(kept));
  // The lower median: a warm-up that took longer than the frames after it
  // counts for no more than they do once there are two of them.
  const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>((kept - 1) / 2);
  std::nth_element(sorted.begin(), middle, sorted.end());
  return *middle;
}

clock::Nanos RenderPace::allowance(clock::Nanos frame_timeout, clock::Nanos longest, bool captured) const {
  const std::size_t kept = std::min(count_, kKept);
  const clock::Nanos slowest =
      kept == 0 ? 0 : *std::max_element(rounds_.begin(), rounds_.begin() + static_cast<std::ptrdiff_t>(kept));
  return std::max(frame_timeout, std::min(2 * (slowest + (captured ? capture_ : 0)), longest));
}

}  // namespace optique::master
