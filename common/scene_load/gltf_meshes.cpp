// The loader's meshes: a glTF mesh's primitives (triangles, from accessors or
// Draco) into the scene's meshes, each with its material.
#include "scene_load/gltf_loader.h"

#include <algorithm>
#include <cmath>

#include "scene_load/draco_primitive.h"
#include "util/finite.h"

namespace optique::scene {

using util::finite;

const std::vector<Loader::Part>& Loader::parts_of(std::size_t mesh_index, std::size_t node) {
  if (mesh_index >= model_.meshes.size()) {
    fail(node_label(node) + ": mesh " + std::to_string(mesh_index) + " is out of range");
  }
  if (parts_.size() < model_.meshes.size()) parts_.resize(model_.meshes.size());
  auto& cached = parts_[mesh_index];
  if (!cached) {
    std::vector<Part> parts;
    const auto& mesh = model_.meshes[mesh_index];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      if (auto part = convert_primitive(mesh_index, p)) parts.push_back(*part);
    }
    cached = std::move(parts);
  }
  return *cached;
}

// An attribute's values, checked to be one per vertex.
std::vector<double> Loader::per_vertex(std::vector<double> values, std::size_t width, std::size_t vertex_count,
                                       const std::string& label, const std::string& name) const {
  if (values.size() / width != vertex_count) {
    fail(label + ": " + name + " has " + std::to_string(values.size() / width) + " elements but POSITION has " +
         std::to_string(vertex_count));
  }
  return values;
}

// Texture coordinates: FLOAT, or normalized UNSIGNED_BYTE / UNSIGNED_SHORT.
std::vector<double> Loader::read_uvs(int index, const std::string& label) const {
  const auto& acc = data_.accessor(index, label + " TEXCOORD_0");
  if (acc.componentType == TINYGLTF_COMPONENT_TYPE_BYTE || acc.componentType == TINYGLTF_COMPONENT_TYPE_SHORT) {
    fail(data_.accessor_label(index, label + " TEXCOORD_0") + ": component type " +
         component_type_name(acc.componentType) +
         " is not allowed for texture coordinates (FLOAT, or normalized UNSIGNED_BYTE or UNSIGNED_SHORT)");
  }
  return data_.read_floats(index, label + " TEXCOORD_0", TINYGLTF_TYPE_VEC2, /*normalized_ok=*/true);
}

std::optional<int> Loader::attribute(const tinygltf::Primitive& primitive, const std::string& name) {
  const auto found = primitive.attributes.find(name);
  if (found == primitive.attributes.end()) return std::nullopt;
  return found->second;
}

Loader::Attributes Loader::read_accessors(const tinygltf::Primitive& primitive, const std::string& label) const {
  Attributes out;
  const auto position = attribute(primitive, "POSITION");
  if (!position) fail(label + " has no POSITION attribute");
  out.positions = data_.read_floats(*position, label + " POSITION", TINYGLTF_TYPE_VEC3);
  const std::size_t vertex_count = out.positions.size() / 3;
  if (vertex_count > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many vertices");
  if (const auto normal = attribute(primitive, "NORMAL")) {
    out.normals =
        per_vertex(data_.read_floats(*normal, label + " NORMAL", TINYGLTF_TYPE_VEC3), 3, vertex_count, label, "NORMAL");
  }
  if (const auto uv = attribute(primitive, "TEXCOORD_0")) {
    out.uvs = per_vertex(read_uvs(*uv, label), 2, vertex_count, label, "TEXCOORD_0");
  }
  if (primitive.indices >= 0) {
    out.order = data_.read_indices(primitive.indices, label + " indices");
    for (std::size_t i = 0; i < out.order.size(); ++i) {
      if (out.order[i] >= vertex_count) {
        fail(label + ": index " + std::to_string(out.order[i]) + " (at " + std::to_string(i) +
             ") is out of range: there are " + std::to_string(vertex_count) + " vertices");
      }
    }
  } else {
    out.order.resize(vertex_count);
    for (std::size_t i = 0; i < vertex_count; ++i) out.order[i] = static_cast<std::uint32_t>(i);
  }
  return out;
}

// A KHR_draco_mesh_compression primitive: the attributes the extension maps
// come from the compressed data, any other from its accessor (the extension
// allows both); the accessors' counts must agree with what was decoded.
Loader::Attributes Loader::read_draco(const tinygltf::Primitive& primitive, const std::string& label,
                                      std::int64_t indices, int mode) const {
  const std::string what = label + ": " + kDracoExtension;
  if (mode != TINYGLTF_MODE_TRIANGLES) fail(what + " needs mode TRIANGLES");
  if (indices < -1) fail(what + ": its indices are not an accessor's index");
  const auto found = primitive.extensions.find(kDracoExtension);
  if (found == primitive.extensions.end() || !found->second.IsObject() || !found->second.Get("bufferView").IsInt() ||
      !found->second.Get("attributes").IsObject()) {
    fail(what + " must be an object with a bufferView and attributes");
  }
  const tinygltf::Value& extension = found->second;
  const std::span<const unsigned char> compressed =
      data_.view_bytes(extension.Get("bufferView").GetNumberAsInt(), what);
  const tinygltf::Value& ids = extension.Get("attributes");
  const auto id_of = [&](const std::string& name) -> std::optional<int> {
    if (!ids.Has(name)) return std::nullopt;
    if (!ids.Get(name).IsInt()) fail(what + ": the id of " + name + " is not an integer");
    return ids.Get(name).GetNumberAsInt();
  };
  const auto position = attribute(primitive, "POSITION");
  if (!position) fail(label + " has no POSITION attribute");
  const auto position_id = id_of("POSITION");
  if (!position_id) fail(what + " does not compress POSITION");
  const bool has_normal = attribute(primitive, "NORMAL").has_value();
  const bool has_uv = attribute(primitive, "TEXCOORD_0").has_value();
  const std::optional<int> normal_id = has_normal ? id_of("NORMAL") : std::nullopt;
  const std::optional<int> uv_id = has_uv ? id_of("TEXCOORD_0") : std::nullopt;
  auto decoded =
      decode_draco_primitive(std::string_view(reinterpret_cast<const char*>(compressed.data()), compressed.size()),
                             *position_id, normal_id, uv_id);
  if (!decoded) fail(what + ": " + decoded.error());
  DracoPrimitive& mesh = decoded.value();
  if (mesh.points > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many vertices");
  const auto expect_count = [&](int index, std::size_t count, const std::string& name) {
    const auto& acc = data_.accessor(index, label + " " + name);
    if (acc.count != count) {
      fail(what + ": " + data_.accessor_label(index, label + " " + name) + " has count " + std::to_string(acc.count) +
           " but the compressed data holds " + std::to_string(count));
    }
  };
  expect_count(*position, mesh.points, "POSITION");
  if (indices >= 0) expect_count(static_cast<int>(indices), mesh.indices.size(), "indices");
  Attributes out;
  out.positions = std::move(mesh.positions);
  if (has_normal) {
    out.normals =
        normal_id
            ? std::move(mesh.normals)
            : per_vertex(data_.read_floats(*attribute(primitive, "NORMAL"), label + " NORMAL", TINYGLTF_TYPE_VEC3), 3,
                         mesh.points, label, "NORMAL");
  }
  if (has_uv) {
    out.uvs =
        uv_id ? std::move(mesh.uvs)
              : per_vertex(read_uvs(*attribute(primitive, "TEXCOORD_0"), label), 2, mesh.points, label, "TEXCOORD_0");
  }
  out.order = std::move(mesh.indices);
  return out;
}

std::optional<Loader::Part> Loader::convert_primitive(std::size_t mesh_index, std::size_t p) {
  const auto& mesh = model_.meshes[mesh_index];
  const auto& primitive = mesh.primitives[p];
  const std::string label = labelled("mesh", mesh_index, mesh.name) + " primitive " + std::to_string(p);

  const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
  switch (mode) {
    case TINYGLTF_MODE_TRIANGLES:
    case TINYGLTF_MODE_TRIANGLE_STRIP:
    case TINYGLTF_MODE_TRIANGLE_FAN:
      break;
    case TINYGLTF_MODE_POINTS:
      fail(label + ": primitive mode POINTS is not supported (triangles only)");
    case TINYGLTF_MODE_LINE:
    case TINYGLTF_MODE_LINE_LOOP:
    case TINYGLTF_MODE_LINE_STRIP:
      fail(label + ": primitive mode LINES is not supported (triangles only)");
    default:
      fail(label + ": primitive mode " + std::to_string(mode) + " is not supported (triangles only)");
  }
  if (!primitive.targets.empty()) fail(label + ": morph targets are not supported");

  Attributes read = source_.draco_indices.contains({mesh_index, p})
                        ? read_draco(primitive, label, source_.draco_indices.at({mesh_index, p}), mode)
                        : read_accessors(primitive, label);
  const std::vector<double>& positions = read.positions;
  const std::vector<double>& normals = read.normals;
  const std::vector<double>& uvs = read.uvs;
  const std::size_t vertex_count = positions.size() / 3;
  const auto uv = [&](std::uint32_t i) {
    if (uvs.empty()) return glm::vec2(0.0f);
    return glm::vec2(static_cast<float>(uvs[2 * i]), static_cast<float>(uvs[2 * i + 1]));
  };
  std::vector<std::uint32_t> order = std::move(read.order);

  // As a triangle list: strips and fans as the glTF spec orders them.
  std::vector<std::uint32_t> triangles;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (order.size() % 3 != 0) {
      fail(label + ": " + std::to_string(order.size()) + " indices are not a whole number of triangles");
    }
    triangles = std::move(order);
  } else {
    for (std::size_t i = 0; i + 2 < order.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        const bool odd = i % 2 == 1;
        triangles.insert(triangles.end(), {order[i], order[odd ? i + 2 : i + 1], order[odd ? i + 1 : i + 2]});
      } else {
        triangles.insert(triangles.end(), {order[i + 1], order[i + 2], order[0]});
      }
    }
  }
  if (triangles.empty()) {
    warn(label + " has no triangles; skipped");
    return std::nullopt;
  }

  Mesh out;
  out.name = mesh.name.empty() ? "mesh " + std::to_string(mesh_index) : mesh.name;
  if (mesh.primitives.size() > 1) out.name += " #" + std::to_string(p);
  const auto position = [&](std::uint32_t i) {
    return glm::vec3(static_cast<float>(positions[3 * i]), static_cast<float>(positions[3 * i + 1]),
                     static_cast<float>(positions[3 * i + 2]));
  };
  if (!normals.empty()) {
    // Unit length, as the renderer expects; a zero normal (invalid glTF) points
    // along +z rather than becoming NaN.
    out.vertices.reserve(vertex_count);
    bool degenerate = false;
    for (std::size_t i = 0; i < vertex_count; ++i) {
      const glm::dvec3 given(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
      const double length = glm::length(given);
      glm::vec3 normal(0.0f, 0.0f, 1.0f);
      if (length > 1e-20 && std::isfinite(length)) {
        normal = glm::vec3(given / length);
      } else {
        degenerate = true;
      }
      out.vertices.push_back({position(static_cast<std::uint32_t>(i)), normal, uv(static_cast<std::uint32_t>(i))});
    }
    if (degenerate) warn(label + ": some normals have zero length; they point along +z");
    out.indices = std::move(triangles);
  } else {
    // Flat normals: each triangle its own three vertices.
    if (triangles.size() > std::numeric_limits<std::uint32_t>::max()) fail(label + " has too many triangles");
    out.vertices.reserve(triangles.size());
    out.indices.reserve(triangles.size());
    for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
      const glm::dvec3 a(position(triangles[t]));
      const glm::dvec3 b(position(triangles[t + 1]));
      const glm::dvec3 c(position(triangles[t + 2]));
      const glm::dvec3 cross = glm::cross(b - a, c - a);
      const double length = glm::length(cross);
      const glm::vec3 normal =
          length > 0.0 && std::isfinite(length) ? glm::vec3(cross / length) : glm::vec3(0.0f, 0.0f, 1.0f);
      for (int k = 0; k < 3; ++k) {
        out.indices.push_back(static_cast<std::uint32_t>(out.vertices.size()));
        const std::uint32_t corner = triangles[t + static_cast<std::size_t>(k)];
        out.vertices.push_back({position(corner), normal, uv(corner)});
      }
    }
  }
  for (const auto& vertex : out.vertices) {
    if (!finite(glm::dvec3(vertex.position)) || !finite(glm::dvec3(vertex.normal)) || !std::isfinite(vertex.uv.x) ||
        !std::isfinite(vertex.uv.y)) {
      fail(label + ": a vertex is not finite in single precision");
    }
  }

  Part part;
  part.material = material(primitive.material, label);
  if (uvs.empty() && materials_[part.material].base_colour_texture) {
    warn(label + " has no TEXCOORD_0; its base colour texture is sampled at (0, 0) only");
  }
  meshes_.push_back(std::move(out));
  part.mesh = static_cast<std::uint32_t>(meshes_.size() - 1);
  return part;
}

}  // namespace optique::scene
