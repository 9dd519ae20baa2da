#pragma once
// Internal to scene: what the glTF loader's parts throw when a file is wrong
// (caught in load_gltf, which returns it as an Error: the message already
// starts with the path), and how they name what is wrong.

#include <cstddef>
#include <stdexcept>
#include <string>

namespace optique::scene {

class GltfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "node 3 'wheel'": a glTF object by kind, index and name (when it has one).
[[nodiscard]] inline std::string labelled(const std::string& kind, std::size_t index, const std::string& name) {
  std::string label = kind + " " + std::to_string(index);
  if (!name.empty()) label += " '" + name + "'";
  return label;
}

}  // namespace optique::scene
