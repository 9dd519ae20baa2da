#pragma once
// Reading the homography back from a file that `optique-master calibrate` wrote,
// for configs that name a projector's calibration file.

#include <cstdint>
#include <string>

#include <glm/mat3x3.hpp>

#include "util/result.h"

namespace optique::config {

// The file's "homography" (3×3, row-major rows, screen metres → projector
// pixels), for a projector of `width` × `height` pixels. Fails, naming the file
// and the field, when it is missing, not 3×3 or not finite, and when the file was
// fitted for an image of another size (its "projector": width and height): its
// pixels would land in the wrong places.
[[nodiscard]] Result<glm::dmat3> read_calibration_homography(const std::string& path, std::uint32_t width,
                                                             std::uint32_t height);

}  // namespace optique::config
