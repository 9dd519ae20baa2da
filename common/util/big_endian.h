#pragma once
// Whole numbers written most significant byte first, as the hello's MAC and
// the session keys' derivation frame their fields.

#include <cstdint>
#include <vector>

namespace optique::util {

inline void append_be32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(value >> shift));
}

}  // namespace optique::util
