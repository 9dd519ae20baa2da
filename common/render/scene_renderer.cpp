#include "render/scene_renderer.h"

#include <cassert>
#include <string>

#include "render/renderer_parts.h"

namespace optique::render {

SceneRenderer::SceneRenderer(std::unique_ptr<RendererParts> parts) : parts_(std::move(parts)) {}
SceneRenderer::~SceneRenderer() = default;

Result<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const scene::SceneDefinition& scene, int width, int height,
                                                             DepthFormat depth, int samples) {
  if (width <= 0 || height <= 0) return Error{"the image size must be positive"};
  if (samples < 1) return Error{"the samples per pixel must be at least 1, not " + std::to_string(samples)};
  auto scene_pass = ScenePass::create(scene);
  if (!scene_pass) return Error{scene_pass.error()};
  const GLenum depth_format = depth == DepthFormat::fixed24 ? GL_DEPTH_COMPONENT24 : GL_DEPTH_COMPONENT32F;
  auto linear = LinearTarget::create(width, height, depth_format, samples);
  if (!linear) return Error{linear.error()};
  auto parts = std::make_unique<RendererParts>(std::move(scene_pass).value(), std::move(linear).value());
  if (auto output = parts->output.set({}); !output) return Error{output.error()};
  return std::unique_ptr<SceneRenderer>(new SceneRenderer(std::move(parts)));
}

void SceneRenderer::draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms) {
  parts_->draw_linear(state, view, terms);
  parts_->encode();
}

void SceneRenderer::draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                const LightTerms& terms, bool still_once) {
  parts_->draw_fields(state, passes, terms, still_once);
  parts_->encode();
}

void SceneRenderer::draw_black() {
  RendererParts& parts = *parts_;
  parts.rendered_is_linear();
  glBindFramebuffer(GL_FRAMEBUFFER, parts.linear.framebuffer());
  glViewport(0, 0, parts.linear.format().width, parts.linear.format().height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  parts.encode();
}

void SceneRenderer::set_lights(std::span<const std::uint32_t> lights) { parts_->scene.set_lights(lights); }

Result<void> SceneRenderer::add_asset(const scene::SceneDefinition& asset) { return parts_->scene.add_asset(asset); }

Result<void> SceneRenderer::prepare_gather() {
  if (gather_) return {};
  auto gather = GatherPasses::create(*parts_);
  if (!gather) return Error{gather.error()};
  gather_ = std::move(gather).value();
  return {};
}

GatherPasses& SceneRenderer::gather() {
  assert(gather_);  // prepare_gather first
  return *gather_;
}

Result<void> SceneRenderer::prepare_up_conversion(int slots) {
  if (up_) return {};
  auto up = UpConversionPasses::create(*parts_, slots);
  if (!up) return Error{up.error()};
  up_ = std::move(up).value();
  return {};
}

UpConversionPasses& SceneRenderer::up_conversion() {
  assert(up_);  // prepare_up_conversion first
  return *up_;
}

OutputPass& SceneRenderer::output() { return parts_->output; }
const OutputPass& SceneRenderer::output() const { return parts_->output; }

image::FloatImage SceneRenderer::read_rendered() const {
  const LinearFormat& format = parts_->linear.format();
  image::FloatImage image = glo::read_float(parts_->rendered_colour, format.width, format.height, GL_RGBA, 4);
  for (std::size_t i = 3; i < image.pixels.size(); i += 4) image.pixels[i] = 1.0f;
  return image;
}

image::FloatImage SceneRenderer::read_depth() const {
  const LinearFormat& format = parts_->linear.format();
  return glo::read_float(parts_->rendered_depth, format.width, format.height, GL_DEPTH_COMPONENT, 1);
}

unsigned SceneRenderer::rendered_framebuffer() const { return parts_->rendered_colour; }

}  // namespace optique::render
