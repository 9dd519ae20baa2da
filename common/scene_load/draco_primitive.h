#pragma once
// A mesh primitive compressed with KHR_draco_mesh_compression, decoded with
// Google's Draco library (Debian's libdraco): its triangles and the attributes
// the renderer draws, as plain numbers, every point's values in point order.

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "util/result.h"

namespace optique::scene {

struct DracoPrimitive {
  std::size_t points = 0;
  std::vector<double> positions;       // 3 a point
  std::vector<double> normals;         // 3 a point, when asked for
  std::vector<double> uvs;             // 2 a point, when asked for
  std::vector<std::uint32_t> indices;  // 3 a triangle, each below `points`
};

// Decodes `bytes` (the extension's buffer view); the attributes are the Draco
// unique ids the extension maps POSITION, NORMAL and TEXCOORD_0 to. Fails,
// saying why, on data Draco cannot decode, a point cloud, a missing attribute or
// one with too few components, or values that are not finite.
[[nodiscard]] Result<DracoPrimitive> decode_draco_primitive(std::string_view bytes, int position_id,
                                                            std::optional<int> normal_id, std::optional<int> uv_id);

}  // namespace optique::scene
