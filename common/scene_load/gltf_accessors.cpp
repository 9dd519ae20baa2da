#include "scene_load/gltf_accessors.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "scene_load/gltf_error.h"

namespace optique::scene {

std::string type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
      return "VEC2";
    case TINYGLTF_TYPE_VEC3:
      return "VEC3";
    case TINYGLTF_TYPE_VEC4:
      return "VEC4";
    case TINYGLTF_TYPE_MAT2:
      return "MAT2";
    case TINYGLTF_TYPE_MAT3:
      return "MAT3";
    case TINYGLTF_TYPE_MAT4:
      return "MAT4";
    default:
      return "type " + std::to_string(type);
  }
}

std::string component_type_name(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
      return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_DOUBLE:
      return "DOUBLE";
    default:
      return "component type " + std::to_string(component_type);
  }
}

namespace {

std::size_t component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

std::size_t component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

// One component at `p`, as a double; normalized integers map to [0, 1] or [−1, 1].
double read_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v = 0.0f;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      const std::uint8_t v = *p;
      return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v = 0;
      std::memcpy(&v, p, sizeof v);
      return v;
    }
    default:
      return 0.0;
  }
}

}  // namespace

void GltfAccessors::fail(const std::string& what) const { throw GltfError(path_ + ": " + what); }

std::string GltfAccessors::accessor_label(int index, const std::string& what) const {
  return "accessor " + std::to_string(index) + " (" + what + ")";
}

const tinygltf::Accessor& GltfAccessors::accessor(int index, const std::string& what) const {
  if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size()) {
    fail(accessor_label(index, what) + " is out of range: the file has " + std::to_string(model_.accessors.size()) +
         " accessors");
  }
  return model_.accessors[static_cast<std::size_t>(index)];
}

// The bytes of buffer view `index` (for `label`), after checking that the view
// and its buffer exist and that the view lies inside the buffer.
std::span<const unsigned char> GltfAccessors::view_bytes(int index, const std::string& label) const {
  const std::string view_label = "buffer view " + std::to_string(index);
  if (index < 0 || static_cast<std::size_t>(index) >= model_.bufferViews.size()) {
    fail(label + ": " + view_label + " is out of range");
  }
  const auto& view = model_.bufferViews[static_cast<std::size_t>(index)];
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size()) {
    fail(label + ": " + view_label + " names buffer " + std::to_string(view.buffer) + ", which is out of range");
  }
  const auto& buffer = model_.buffers[static_cast<std::size_t>(view.buffer)];
  if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset) {
    fail(label + ": " + view_label + " (bytes " + std::to_string(view.byteOffset) + " + " +
         std::to_string(view.byteLength) + ") is out of range of buffer " + std::to_string(view.buffer) + " (" +
         std::to_string(buffer.data.size()) + " bytes)");
  }
  return {buffer.data.data() + view.byteOffset, view.byteLength};
}

// Where the elements of accessor `index` are, each `element_size` bytes, after
// checking that all of them lie inside their buffer view and buffer.
GltfAccessors::Located GltfAccessors::locate(int index, const std::string& what, std::size_t element_size) const {
  const auto& acc = accessor(index, what);
  const std::string label = accessor_label(index, what);
  if (acc.sparse.isSparse) fail(label + ": sparse accessors are not supported");
  if (acc.count == 0) return {};
  if (acc.bufferView < 0) fail(label + ": accessors without a buffer view are not supported");
  const std::span<const unsigned char> bytes = view_bytes(acc.bufferView, label);
  const auto& view = model_.bufferViews[static_cast<std::size_t>(acc.bufferView)];
  const std::string view_label = "buffer view " + std::to_string(acc.bufferView);
  const std::size_t stride = view.byteStride != 0 ? view.byteStride : element_size;
  if (stride < element_size) {
    fail(label + ": byteStride " + std::to_string(stride) + " is smaller than an element (" +
         std::to_string(element_size) + " bytes)");
  }
  if (acc.byteOffset > view.byteLength || element_size > view.byteLength - acc.byteOffset ||
      (acc.count - 1) > (view.byteLength - acc.byteOffset - element_size) / stride) {
    fail(label + ": " + std::to_string(acc.count) + " elements from byte " + std::to_string(acc.byteOffset) +
         " are out of range of " + view_label + " (" + std::to_string(view.byteLength) + " bytes)");
  }
  return {bytes.data() + acc.byteOffset, stride, acc.count};
}

// The components of accessor `index`, which must be of `type` and FLOAT (or,
// where `normalized_ok`, normalized integers), all finite.
std::vector<double> GltfAccessors::read_floats(int index, const std::string& what, int type, bool normalized_ok) const {
  const auto& acc = accessor(index, what);
  const std::string label = accessor_label(index, what);
  if (acc.type != type) fail(label + " must be " + type_name(type) + ", not " + type_name(acc.type));
  const bool is_float = acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  const bool normalized_int = normalized_ok && acc.normalized &&
                              (acc.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                               acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                               acc.componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
                               acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
  if (!is_float && !normalized_int) {
    fail(label + ": component type " + component_type_name(acc.componentType) +
         (acc.normalized ? " (normalized)" : "") + " is not supported here (FLOAT only" +
         (normalized_ok ? ", or normalized integers" : "") + ")");
  }
  const std::size_t components = component_count(type);
  const std::size_t size = component_size(acc.componentType);
  const Located where = locate(index, what, components * size);
  std::vector<double> out;
  out.reserve(where.count * components);
  for (std::size_t i = 0; i < where.count; ++i) {
    const unsigned char* element = where.data + i * where.stride;
    for (std::size_t c = 0; c < components; ++c) {
      const double v = read_component(element + c * size, acc.componentType, acc.normalized);
      if (!std::isfinite(v)) fail(label + ": element " + std::to_string(i) + " is not a finite number");
      out.push_back(v);
    }
  }
  return out;
}

std::vector<std::uint32_t> GltfAccessors::read_indices(int index, const std::string& what) const {
  const auto& acc = accessor(index, what);
  const std::string label = accessor_label(index, what);
  if (acc.type != TINYGLTF_TYPE_SCALAR) fail(label + " must be SCALAR, not " + type_name(acc.type));
  if (acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    fail(label + ": component type " + component_type_name(acc.componentType) +
         " is not an index type (UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)");
  }
  const Located where = locate(index, what, component_size(acc.componentType));
  std::vector<std::uint32_t> out;
  out.reserve(where.count);
  for (std::size_t i = 0; i < where.count; ++i) {
    out.push_back(static_cast<std::uint32_t>(read_component(where.data + i * where.stride, acc.componentType, false)));
  }
  return out;
}

}  // namespace optique::scene
