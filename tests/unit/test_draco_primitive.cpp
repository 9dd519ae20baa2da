// A Draco-compressed primitive (scene_load/draco_primitive.h) from bytes Draco's own
// encoder wrote: a triangle decodes to its points, and one whose stored index
// names a point the mesh does not have is refused (Draco's sequential format
// stores indices as plain bytes, and its decoder takes them as they are).

#include "scene_load/draco_primitive.h"

#include <gtest/gtest.h>

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <array>
#include <string>

namespace optique::scene {
namespace {

// One triangle of three points, sequentially encoded (its indices stored raw,
// a byte each); the POSITION attribute's unique id in `position_id`.
std::string encoded_triangle(int& position_id) {
  draco::Mesh mesh;
  mesh.set_num_points(3);
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
  const int attribute = mesh.AddAttribute(position, true, 3);
  const std::array<std::array<float, 3>, 3> corners{{{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}};
  for (std::uint32_t i = 0; i < 3; ++i) {
    mesh.attribute(attribute)->SetAttributeValue(draco::AttributeValueIndex(i), corners[i].data());
  }
  mesh.AddFace({draco::PointIndex(0), draco::PointIndex(1), draco::PointIndex(2)});
  position_id = static_cast<int>(mesh.attribute(attribute)->unique_id());
  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  EXPECT_TRUE(status.ok()) << status.error_msg_string();
  return {buffer.data(), buffer.size()};
}

TEST(DracoPrimitive, ATriangleDecodesToItsPoints) {
  int position_id = 0;
  const std::string bytes = encoded_triangle(position_id);
  const auto decoded = decode_draco_primitive(bytes, position_id, std::nullopt, std::nullopt);
  ASSERT_TRUE(decoded) << decoded.error();
  EXPECT_EQ(decoded.value().points, 3u);
  ASSERT_EQ(decoded.value().indices.size(), 3u);
  for (const std::uint32_t index : decoded.value().indices) EXPECT_LT(index, 3u);
}

TEST(DracoPrimitive, ATriangleNamingAPointPastTheMeshsIsRefused) {
  int position_id = 0;
  std::string bytes = encoded_triangle(position_id);
  // The connectivity: 1 face, 3 points, raw indices (method 1), then 0 1 2.
  const std::string connectivity("\x01\x03\x01\x00\x01\x02", 6);
  const std::size_t at = bytes.find(connectivity);
  ASSERT_NE(at, std::string::npos) << "the sequential connectivity as Draco's format gives it";
  bytes[at + 4] = static_cast<char>(200);  // the face's second corner: point 200 of 3
  const auto decoded = decode_draco_primitive(bytes, position_id, std::nullopt, std::nullopt);
  ASSERT_FALSE(decoded);
  EXPECT_NE(decoded.error().find("names point 200 of 3"), std::string::npos) << decoded.error();
}

}  // namespace
}  // namespace optique::scene
