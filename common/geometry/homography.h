#pragma once
// A projector's homography H: screen coordinates (metres, in the screen's own
// frame: origin lower-left, y up) → projector pixels (origin at the image's
// top-left corner, x right, y down, pixel centres at half-integers),
// [x y 1]ᵀ ≅ H [X Y 1]ᵀ. glm matrices are column-major: h[col][row].
//
// The fit itself is in calib/fit.h (DLT, refinement, robust mode, diagnostics).

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

namespace optique::geometry {

struct Correspondence {
  glm::dvec2 screen;  // metres on the screen
  glm::dvec2 pixel;   // projector pixel
};

// A projector's image in pixels: corners (0, 0) and (width, height).
struct ImageSize {
  int width = 0;
  int height = 0;
};

// Maps a screen point to pixels.
[[nodiscard]] glm::dvec2 apply(const glm::dmat3& homography, const glm::dvec2& screen);

// The homogeneous w of a screen point, (H·[X Y 1]ᵀ)_z: its sign says on which
// side of the projector's horizon the point is.
[[nodiscard]] double homogeneous_w(const glm::dmat3& homography, const glm::dvec2& screen);

// Distance in pixels between where H puts the screen point and the measured pixel.
[[nodiscard]] double reprojection_error(const glm::dmat3& homography, const Correspondence& point);

}  // namespace optique::geometry
