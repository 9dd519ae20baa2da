#pragma once
// The lights a node of a stacked group draws, as master and node agree on them.

#include <cstdint>
#include <vector>

namespace optique::protocol {

struct LightShare {
  std::vector<std::uint32_t> lights;  // indices into the scene's lights, ascending, unique
  bool ambient = false;               // also the ambient and emissive terms

  friend bool operator==(const LightShare&, const LightShare&) = default;
};

}  // namespace optique::protocol
