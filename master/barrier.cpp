#include "master/barrier.h"

#include <algorithm>

namespace optique::master {

void Barrier::begin(std::uint64_t frame, std::vector<std::size_t> expected) {
  frame_ = frame;
  waiting_ = std::move(expected);
  active_ = true;
}

bool Barrier::ready(std::size_t slot) {
  const auto it = std::find(waiting_.begin(), waiting_.end(), slot);
  if (it == waiting_.end()) return false;
  waiting_.erase(it);
  return true;
}

void Barrier::leave(std::size_t slot) { std::erase(waiting_, slot); }

}  // namespace optique::master
