#pragma once
// The node's real renderer: an OpenGL context (headless or a window, from the
// projector's output), the scene drawn through the projector's part of its screen
// from the viewer's eye (or one eye), shown on present(), and captured on request.

#include <memory>
#include <optional>
#include <string>

#include <spdlog/logger.h>

#include "geometry/projection.h"
#include "node/gl/capture_writer.h"
#include "node/renderer.h"
#include "render/gl_context.h"
#include "render/projector_view.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"

namespace optique::node {

class GlRenderer final : public Renderer {
 public:
  // Captures go to `capture_folder`/frame-NNNNNN.{exr,png}.
  GlRenderer(spdlog::logger& log, std::string capture_folder);
  ~GlRenderer() override;

  [[nodiscard]] Result<void> configure(const wire::Welcome& welcome) override;
  [[nodiscard]] std::string description() const override;
  void render(const FrameInput& frame) override;
  void present() override;
  void show_black() override;

 private:
  // Draws these lights from now on, and ambient and emissive light if it carries them.
  void draw_share(const wire::LightShare& share);

  spdlog::logger& log_;
  std::string capture_folder_;
  std::string configured_for_;  // the welcome's projector and scene, to skip rebuilding on a rejoin
  std::unique_ptr<render::GlContext> context_;
  std::unique_ptr<render::SceneRenderer> renderer_;
  std::optional<CaptureWriter> captures_;
  std::optional<render::ProjectorView> view_;
  geometry::Eye eye_ = geometry::Eye::mono;
  glm::dvec3 head_right_{1.0, 0.0, 0.0};
  double eye_separation_ = 0.0;
  double near_ = 0.05;
  double far_ = 100.0;
  render::LightTerms terms_;
  bool deep_signal_ = false;  // the projector takes more than 8 bits: captures are 16-bit PNGs
  render::FocusRole focus_role_ = render::FocusRole::none;
  config::DepthOfField depth_of_field_;  // resolved by the master: near/far set
};

}  // namespace optique::node
