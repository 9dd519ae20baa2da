#include "render/projector_view.h"

#include <algorithm>
#include <cmath>

#include <glm/matrix.hpp>

namespace optique::render {

FocusRole focus_role(config::ContentRole role) {
  if (role == config::ContentRole::focus) return FocusRole::focus;
  if (role == config::ContentRole::defocus) return FocusRole::defocus;
  return FocusRole::none;
}

Result<ProjectorView> ProjectorView::make(const config::Screen& screen, const geometry::ProjectorGeometry& geometry,
                                          RenderMethod method, double two_pass_pixels_per_metre) {
  auto oblique = geometry::oblique_projection(geometry, screen.area());
  if (!oblique) return Error{oblique.error()};
  ProjectorView view;
  view.method_ = method;
  view.oblique_ = oblique.value();
  const geometry::ScreenRect& r = view.oblique_.bounds;
  view.bounds_ = screen.world(r);
  view.width_ = geometry.width();
  view.height_ = geometry.height();
  view.pixel_to_screen_ = geometry.pixel_to_screen();
  view.max_pixels_per_metre_ = geometry.max_pixels_per_metre();
  if (method == RenderMethod::single_pass) {
    view.render_width_ = geometry.width();
    view.render_height_ = geometry.height();
  } else {
    constexpr double kLargest = 8192.0;
    const double density =
        two_pass_pixels_per_metre > 0.0 ? two_pass_pixels_per_metre : geometry.max_pixels_per_metre();
    view.render_width_ = static_cast<int>(std::clamp(std::ceil(r.width() * density), 1.0, kLargest));
    view.render_height_ = static_cast<int>(std::clamp(std::ceil(r.height() * density), 1.0, kLargest));
  }
  return view;
}

Result<geometry::Frustum> ProjectorView::frustum(const glm::dvec3& eye, double near, double far) const {
  auto frustum = geometry::off_axis_frustum(bounds_, eye, near, far);
  if (!frustum) return frustum;
  if (method_ == RenderMethod::single_pass) frustum.value().projection = oblique_.matrix() * frustum.value().projection;
  return frustum;
}

OutputStage ProjectorView::output_stage(image::FloatImage weights, FocusRole role) const {
  OutputStage stage;
  stage.width = width_;
  stage.height = height_;
  if (method_ == RenderMethod::two_pass) stage.projector_to_user = glm::inverse(oblique_.user_to_projector);
  stage.weights = std::move(weights);
  if (role != FocusRole::none) {
    stage.focus.role = role;
    stage.focus.user_to_projector = oblique_.user_to_projector;
    stage.focus.depth_scale = oblique_.depth_scale;
    // The output pass's fragments have rows going up: flip to projector pixels
    // (rows down), then H⁻¹ to the screen.
    const glm::dmat3 flip(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, static_cast<double>(height_), 1.0);
    stage.focus.fragment_to_screen = pixel_to_screen_ * flip;
    stage.focus.screen_metres_per_pixel = 1.0 / max_pixels_per_metre_;
  }
  return stage;
}

}  // namespace optique::render
