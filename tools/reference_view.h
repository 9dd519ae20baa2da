#pragma once
// What a viewer should see on one screen image, drawn in this process: the eye's
// view of the whole screen rectangle at the screen's pixels per metre, with the
// renderer the nodes use. render-reference draws one moment; perceive draws many
// moments of a continuous, every-colour-at-once display.

#include <memory>
#include <optional>

#include "config/installation.h"
#include "image/image.h"
#include "render/box_reduce.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "tools/screen_images.h"
#include "util/result.h"

namespace optique::tools {

class ReferenceView {
 public:
  // Needs a current GL context. `supersample` S: S×S samples per pixel, averaged
  // (box filter, linear light), as screen composites integrate each pixel.
  [[nodiscard]] static Result<ReferenceView> make(const config::Installation& installation,
                                                  const scene::SceneDefinition& scene, const ScreenImage& image,
                                                  int supersample = 1);

  // The screen's light in `state`, `fraction` of a frame after its display time
  // (objects and eyes that far on), linear RGBA at the screen's raster.
  [[nodiscard]] Result<image::FloatImage> draw(const scene::SceneState& state, double fraction) const;
  // An asset an application loaded: its live instances are drawn too.
  [[nodiscard]] Result<void> add_asset(const scene::SceneDefinition& asset) { return renderer_->add_asset(asset); }
  // One sample per pixel, what the projectors' signal would encode: for PNGs.
  [[nodiscard]] image::ByteImage encoded() const { return renderer_->output().read_encoded(); }

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] int supersample() const { return supersample_; }

 private:
  ReferenceView(std::unique_ptr<render::SceneRenderer> renderer, std::optional<render::BoxReduce> reduce,
                const config::Installation& installation, const ScreenImage& image, int width, int height,
                int supersample);

  std::unique_ptr<render::SceneRenderer> renderer_;
  std::optional<render::BoxReduce> reduce_;  // when supersampled: the samples averaged by GL
  const config::Viewer* viewer_;
  const config::Screen* screen_;
  config::Eye eye_;
  int width_;
  int height_;
  int supersample_;
};

}  // namespace optique::tools
