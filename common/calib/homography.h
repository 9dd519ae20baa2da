#pragma once
// A projector's homography H: screen coordinates (metres, in the screen's own
// frame) → projector pixels (origin at the image's top-left corner, x right,
// y down, pixel centres at half-integers), [x y 1]ᵀ ≅ H [X Y 1]ᵀ. Fitted from
// measured correspondences by the Hartley-normalized DLT (SVD).

#include <span>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

#include "util/result.h"

namespace optique::calib {

struct Correspondence {
  glm::dvec2 screen;  // metres on the screen
  glm::dvec2 pixel;   // projector pixel
};

struct HomographyFit {
  glm::dmat3 homography{1.0};  // column-major (glm); h33 = 1
  double rms_px = 0.0;         // reprojection error of the correspondences
  double max_px = 0.0;
  double condition = 0.0;  // of the normalized DLT system: σ_max / σ_8
  std::vector<std::string> warnings;
};

// Maps a screen point to pixels.
[[nodiscard]] glm::dvec2 apply(const glm::dmat3& homography, const glm::dvec2& screen);

// Fails, saying why, on fewer than 4 points, non-finite numbers, repeated points,
// or points (on either side) that are all on one line.
[[nodiscard]] Result<HomographyFit> fit_homography(std::span<const Correspondence> points);

}  // namespace optique::calib
