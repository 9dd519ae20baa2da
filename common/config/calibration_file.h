#pragma once
// Reading the homography back from a file that `optique-master calibrate` wrote,
// for configs that name a projector's calibration file.

#include <string>

#include <glm/mat3x3.hpp>

#include "util/result.h"

namespace optique::config {

// The file's "homography" (3×3, row-major rows, screen metres → projector
// pixels). Fails, naming the file and the field, when it is missing, not 3×3 or
// not finite.
[[nodiscard]] Result<glm::dmat3> read_calibration_homography(const std::string& path);

}  // namespace optique::config
