#pragma once
// How one projector draws its share of a screen for the viewer: through R, the
// rectangle bounding what it lights, with either the single-pass oblique
// projection (A′ · P_U, Raskar) or the two-pass baseline (the viewer's image of R,
// then warped by A to projector pixels). Both produce the projector's pixels;
// aligned projectors (A = identity) draw exactly as an off-axis frustum.

#include <glm/vec3.hpp>

#include "config/installation.h"
#include "geometry/projection.h"
#include "geometry/projector_geometry.h"
#include "render/scene_renderer.h"
#include "util/result.h"

namespace optique::render {

using config::RenderMethod;
// A content role's share of the depth of field: focus, defocus, or none.
[[nodiscard]] FocusRole focus_role(config::ContentRole role);

class ProjectorView {
 public:
  // Fails when the projector lights none of the screen's usable area. A two-pass
  // view renders R at `two_pass_pixels_per_metre`; 0: the projector's densest.
  [[nodiscard]] static Result<ProjectorView> make(const config::Screen& screen,
                                                  const geometry::ProjectorGeometry& geometry, RenderMethod method,
                                                  double two_pass_pixels_per_metre = 0.0);

  // The frustum to draw the scene with, for an eye. Fails when the eye is not in
  // front of the screen.
  [[nodiscard]] Result<geometry::Frustum> frustum(const glm::dvec3& eye, double near, double far) const;

  // The size of the image the scene is drawn into: the projector's for a single
  // pass; for two passes, R at the projector's densest pixel pitch by default (so
  // the warp never magnifies), at most 8192 on a side.
  [[nodiscard]] int render_width() const { return render_width_; }
  [[nodiscard]] int render_height() const { return render_height_; }
  // The output stage for these pixels (weights: the blend, or empty), with the
  // share of the depth of field a focus/defocus projector shows.
  [[nodiscard]] OutputStage output_stage(image::FloatImage weights, FocusRole role = FocusRole::none) const;

  [[nodiscard]] const geometry::ObliqueProjection& oblique() const { return oblique_; }
  [[nodiscard]] const geometry::WorldRect& bounds() const { return bounds_; }
  [[nodiscard]] RenderMethod method() const { return method_; }

 private:
  ProjectorView() = default;
  RenderMethod method_ = RenderMethod::single_pass;
  geometry::ObliqueProjection oblique_;
  geometry::WorldRect bounds_;
  glm::dmat3 pixel_to_screen_{1.0};
  double max_pixels_per_metre_ = 1.0;
  int width_ = 0;
  int height_ = 0;
  int render_width_ = 0;
  int render_height_ = 0;
};

}  // namespace optique::render
