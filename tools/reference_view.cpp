#include "tools/reference_view.h"

#include "geometry/projection.h"
#include "optics/compose.h"

namespace optique::tools {

ReferenceView::ReferenceView(std::unique_ptr<render::SceneRenderer> renderer, std::optional<render::BoxReduce> reduce,
                             const config::Installation& installation, const ScreenImage& image, int width, int height,
                             int supersample)
    : renderer_(std::move(renderer)),
      reduce_(std::move(reduce)),
      viewer_(&installation.viewer),
      screen_(image.screen),
      eye_(image.eye),
      width_(width),
      height_(height),
      supersample_(supersample) {}

Result<ReferenceView> ReferenceView::make(const config::Installation& installation, const scene::SceneDefinition& scene,
                                          const ScreenImage& image, int supersample) {
  if (supersample < 1) return Error{"the supersample factor must be at least 1, not " + std::to_string(supersample)};
  const config::Screen& screen = *image.screen;
  // The composite's raster, so the two compare pixel for pixel.
  const int width = optics::screen_pixels(screen.width, screen.pixels_per_metre);
  const int height = optics::screen_pixels(screen.height, screen.pixels_per_metre);
  auto renderer = render::SceneRenderer::create(scene, width * supersample, height * supersample);
  if (!renderer) return Error{renderer.error()};
  std::optional<render::BoxReduce> reduce;
  if (supersample > 1) {
    auto made = render::BoxReduce::make(width, height, supersample);
    if (!made) return Error{made.error()};
    reduce = std::move(made).value();
  }
  return ReferenceView(std::move(renderer).value(), std::move(reduce), installation, image, width, height, supersample);
}

Result<image::FloatImage> ReferenceView::draw(const scene::SceneState& state, double fraction) const {
  const config::Viewer& viewer = *viewer_;
  const glm::dvec3 eye = viewer.eye_in(state, fraction, eye_);
  auto frustum = geometry::off_axis_frustum(screen_->world(), eye, viewer.near, viewer.far);
  if (!frustum) return Error{frustum.error()};
  renderer_->draw(state, render::seen_in_world(state, fraction, eye, frustum.value()));
  if (!reduce_) return renderer_->read_rendered();
  return reduce_->read(renderer_->rendered_framebuffer());
}

}  // namespace optique::tools
