#pragma once
// A list in a message: "a, b, c". The one way lists are joined for people to read.

#include <functional>
#include <string>

namespace optique::util {

// Each of `items` as `text` gives it (the item itself by default: anything a
// std::string can be appended from), separated by ", ".
template <typename Items, typename Text = std::identity>
[[nodiscard]] std::string joined(const Items& items, Text text = {}) {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) out += ", ";
    first = false;
    out += text(item);
  }
  return out;
}

}  // namespace optique::util
