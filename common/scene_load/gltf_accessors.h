#pragma once
// Internal to scene: a glTF file's binary data read through its accessors and
// buffer views, every offset, length, stride, type and value checked against
// the file before anything is read (a bad file throws GltfError naming the
// accessor and what is wrong).

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "scene_load/tinygltf.h"

namespace optique::scene {

// glTF's names for an accessor's type (VEC3…) and component type (FLOAT…).
[[nodiscard]] std::string type_name(int type);
[[nodiscard]] std::string component_type_name(int component_type);

class GltfAccessors {
 public:
  // `path` starts every message.
  GltfAccessors(const tinygltf::Model& model, std::string path) : model_(model), path_(std::move(path)) {}

  // Accessor `index`, used as `what`; fails when there is none.
  [[nodiscard]] const tinygltf::Accessor& accessor(int index, const std::string& what) const;
  [[nodiscard]] std::string accessor_label(int index, const std::string& what) const;
  // The bytes of buffer view `index` (for `label`), after checking that the view
  // and its buffer exist and that the view lies inside the buffer.
  [[nodiscard]] std::span<const unsigned char> view_bytes(int index, const std::string& label) const;
  // The components of accessor `index`, which must be of `type` and FLOAT (or,
  // where `normalized_ok`, normalized integers), all finite.
  [[nodiscard]] std::vector<double> read_floats(int index, const std::string& what, int type,
                                                bool normalized_ok = false) const;
  // Indices: SCALAR, UNSIGNED_BYTE, _SHORT or _INT.
  [[nodiscard]] std::vector<std::uint32_t> read_indices(int index, const std::string& what) const;

 private:
  struct Located {
    const unsigned char* data = nullptr;
    std::size_t stride = 0;
    std::size_t count = 0;
  };
  // Where the elements of accessor `index` are, each `element_size` bytes, after
  // checking that all of them lie inside their buffer view and buffer.
  [[nodiscard]] Located locate(int index, const std::string& what, std::size_t element_size) const;
  [[noreturn]] void fail(const std::string& what) const;

  const tinygltf::Model& model_;
  std::string path_;
};

}  // namespace optique::scene
