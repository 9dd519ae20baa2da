#pragma once
// Where a projector's pixels land on its screen (its homography H, screen metres →
// projector pixels), and the oblique projection that makes its image
// perspectively correct for the viewer in one pass (Raskar, "Immersive Planar
// Display using Roughly Aligned Projectors"; docs/design.md).
//
// Conventions: screen coordinates are metres in the screen's own frame (origin at
// its lower-left corner, y up); projector pixels have their origin at the image's
// top-left corner, x right, y down, pixel centres at half-integers. Projector NDC
// are OpenGL's: (−1, −1) at the image's bottom-left corner.

#include <array>
#include <span>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>

#include "util/result.h"

namespace optique::geometry {

// An axis-aligned rectangle on a screen, metres in the screen frame.
struct ScreenRect {
  glm::dvec2 min{0.0};
  glm::dvec2 max{0.0};

  [[nodiscard]] double width() const { return max.x - min.x; }
  [[nodiscard]] double height() const { return max.y - min.y; }
  [[nodiscard]] bool contains(const glm::dvec2& p) const {
    return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y;
  }
};

// H from nine numbers in row-major order (as configs and calibration files write
// it), and back.
[[nodiscard]] glm::dmat3 homography_from_rows(std::span<const double, 9> rows);
[[nodiscard]] std::array<double, 9> homography_rows(const glm::dmat3& homography);

// The homography of a projector whose image fills `region` exactly, unrotated.
[[nodiscard]] glm::dmat3 aligned_homography(const ScreenRect& region, int width, int height);

class ProjectorGeometry {
 public:
  // Fails when H has non-finite entries, is singular, or sends part of the
  // projector's image to infinity (the screen plane's horizon crosses the image):
  // such a projector cannot be lighting a finite screen.
  [[nodiscard]] static Result<ProjectorGeometry> make(const glm::dmat3& screen_to_pixel, int width, int height);

  [[nodiscard]] glm::dvec2 to_pixel(const glm::dvec2& screen) const;
  [[nodiscard]] glm::dvec2 to_screen(const glm::dvec2& pixel) const;
  [[nodiscard]] const glm::dmat3& screen_to_pixel() const { return screen_to_pixel_; }
  [[nodiscard]] const glm::dmat3& pixel_to_screen() const { return pixel_to_screen_; }
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

  // The image's corners on the screen, in order: top-left, top-right,
  // bottom-right, bottom-left pixel corners. A convex quadrilateral.
  [[nodiscard]] std::array<glm::dvec2, 4> lit_quad() const;
  // Projector pixels per metre of screen along the densest direction, at the
  // densest corner of the image.
  [[nodiscard]] double max_pixels_per_metre() const;

 private:
  ProjectorGeometry(const glm::dmat3& screen_to_pixel, const glm::dmat3& pixel_to_screen, int width, int height);
  glm::dmat3 screen_to_pixel_{1.0};
  glm::dmat3 pixel_to_screen_{1.0};
  int width_ = 0;
  int height_ = 0;
};

// The single-pass projection: P = matrix() · P_U, where P_U is the viewer's
// off-axis frustum through `bounds` (R). A maps user NDC (through R) to projector
// NDC. It is A = N_p · H · N_u⁻¹, signed and scaled so that w = a31·x + a32·y + a33
// lies in [depth_scale, 1] over what the projector shows (its lit quad within the
// usable area). The third row of matrix() is [0 0 depth_scale 0]: Raskar's
// approximated depth (eq. 5), with the bound taken over what is shown instead of
// all of R. It keeps z/w in [−1, 1] for everything between the near and far
// planes that the projector shows; the share of the depth range it keeps at a
// pixel (depth_scale / w) is never smaller than with eq. 5's 1 − |a31| − |a32|
// (the scale of A cancels), and stays away from zero when a corner of R (not
// lit) approaches the projector's horizon (measured: docs/bench/oblique-depth.md).
struct ObliqueProjection {
  ScreenRect bounds;                  // R: the lit quad's bounding rectangle, within the usable area
  glm::dmat3 user_to_projector{1.0};  // A
  double depth_scale = 1.0;

  [[nodiscard]] glm::dmat4 matrix() const;
  [[nodiscard]] glm::dvec2 user_ndc(const glm::dvec2& screen) const;                      // N_u
  [[nodiscard]] glm::dvec2 projector_ndc_to_user(const glm::dvec2& projector_ndc) const;  // A⁻¹
};

// Fails when the projector lights no part of `usable` (the screen area that is
// shown; outside it the projector is masked to black).
[[nodiscard]] Result<ObliqueProjection> oblique_projection(const ProjectorGeometry& geometry, const ScreenRect& usable);

}  // namespace optique::geometry
