#pragma once
// Messages from libraries (tinygltf, OpenImageIO) made fit for one log line: they
// may span lines, or quote a whole base64 data URI.

#include <cstddef>
#include <string>

namespace optique::util {

inline constexpr std::size_t kMaxMessage = 400;

// At most kMaxMessage characters, then "...".
[[nodiscard]] inline std::string shortened(std::string text) {
  if (text.size() > kMaxMessage) {
    text.resize(kMaxMessage);
    text += "...";
  }
  return text;
}

// Line breaks become "; ", trailing blanks go, and the result is shortened.
[[nodiscard]] inline std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.pop_back();
  std::string out;
  for (char c : text) {
    if (c == '\n') {
      out += "; ";
    } else if (c != '\r') {
      out += c;
    }
  }
  return shortened(std::move(out));
}

}  // namespace optique::util
