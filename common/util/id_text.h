#pragma once
// The characters an id may hold (a projector's, a screen's, an application's
// instance's): safe as they are in a file name, a log line and JSON.

namespace optique::util {

[[nodiscard]] constexpr bool is_id_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
}

}  // namespace optique::util
