#include "scene_load/draco_primitive.h"

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cmath>
#include <string>

namespace optique::scene {

namespace {

// Every point's `components` values of attribute `id`, as doubles.
Result<std::vector<double>> read_attribute(const draco::Mesh& mesh, int id, int components, const std::string& name) {
  if (id < 0) return Error{name + ": Draco attribute id " + std::to_string(id) + " is negative"};
  const draco::PointAttribute* attribute = mesh.GetAttributeByUniqueId(static_cast<std::uint32_t>(id));
  if (attribute == nullptr) {
    return Error{name + ": the compressed data has no attribute with id " + std::to_string(id)};
  }
  if (attribute->num_components() < components) {
    return Error{name + ": the compressed attribute has " + std::to_string(attribute->num_components()) +
                 " components, not " + std::to_string(components)};
  }
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(mesh.num_points()) * static_cast<std::size_t>(components));
  float element[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (draco::PointIndex point(0); point < mesh.num_points(); ++point) {
    if (!attribute->ConvertValue<float>(attribute->mapped_index(point), static_cast<std::int8_t>(components),
                                        element)) {
      return Error{name + ": a compressed value cannot be read as a number"};
    }
    for (int c = 0; c < components; ++c) {
      if (!std::isfinite(element[c])) return Error{name + ": a compressed value is not finite"};
      values.push_back(element[c]);
    }
  }
  return values;
}

}  // namespace

Result<DracoPrimitive> decode_draco_primitive(std::string_view bytes, int position_id, std::optional<int> normal_id,
                                              std::optional<int> uv_id) {
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  const auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) return Error{"the compressed data cannot be decoded (" + type.status().error_msg_string() + ")"};
  if (type.value() != draco::TRIANGULAR_MESH) return Error{"the compressed data is not a triangle mesh"};
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    return Error{"the compressed data cannot be decoded (" + decoded.status().error_msg_string() + ")"};
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) return Error{"the compressed data cannot be decoded"};

  DracoPrimitive out;
  out.points = mesh->num_points();
  auto positions = read_attribute(*mesh, position_id, 3, "POSITION");
  if (!positions) return Error{positions.error()};
  out.positions = std::move(positions).value();
  if (normal_id) {
    auto normals = read_attribute(*mesh, *normal_id, 3, "NORMAL");
    if (!normals) return Error{normals.error()};
    out.normals = std::move(normals).value();
  }
  if (uv_id) {
    auto uvs = read_attribute(*mesh, *uv_id, 2, "TEXCOORD_0");
    if (!uvs) return Error{uvs.error()};
    out.uvs = std::move(uvs).value();
  }
  out.indices.reserve(static_cast<std::size_t>(mesh->num_faces()) * 3);
  for (draco::FaceIndex face(0); face < mesh->num_faces(); ++face) {
    for (int corner = 0; corner < 3; ++corner) {
      const std::uint32_t point = mesh->face(face)[corner].value();
      if (point >= out.points)
        return Error{"a compressed triangle names point " + std::to_string(point) + " of " +
                     std::to_string(out.points)};
      out.indices.push_back(point);
    }
  }
  return out;
}

}  // namespace optique::scene
