#include "node/gl/gl_renderer.h"

#include "config/geometry.h"
#include "image/texture_decode.h"
#include "optics/blend.h"
#include "optics/defocus.h"
#include "optics/projector_model.h"
#include "scene/load_scene.h"

namespace optique::node {
namespace {

// This projector's share of the light where it overlaps others of its group (the
// same screen and eye), zero where it is masked outside the usable area.
Result<image::FloatImage> blend_weights(const wire::Welcome& welcome, const geometry::ProjectorGeometry& own) {
  std::vector<geometry::ProjectorGeometry> group;
  std::vector<double> ramps;
  std::size_t self = 0;
  bool found = false;
  for (const auto& member : welcome.blend_group()) {
    auto geometry = config::projector_geometry(member);
    if (!geometry) return Error{"blend partner '" + member.id() + "': " + geometry.error()};
    if (member.id() == welcome.projector().id()) {
      self = group.size();
      found = true;
    }
    group.push_back(std::move(geometry).value());
    ramps.push_back(member.blend_ramp());
  }
  if (!found) {  // a master that sends no group: this projector alone
    self = group.size();
    group.push_back(own);
    ramps.push_back(welcome.projector().blend_ramp());
  }
  const optics::BlendField field(group, config::usable_area(welcome.screen()), ramps);
  return optics::blend_weights(field, group[self], self);
}

}  // namespace

GlRenderer::GlRenderer(spdlog::logger& log, std::string capture_folder)
    : log_(log), capture_folder_(std::move(capture_folder)) {}

GlRenderer::~GlRenderer() {
  captures_.reset();  // finish writing before the GL objects go
  renderer_.reset();
  context_.reset();
}

Result<void> GlRenderer::configure(const wire::Welcome& welcome) {
  const auto& projector = welcome.projector();
  std::string key = projector.SerializeAsString() + welcome.screen().SerializeAsString() +
                    welcome.scene().SerializeAsString() + welcome.viewer().SerializeAsString();
  for (const auto& other : welcome.blend_group()) key += other.SerializeAsString();
  if (key == configured_for_ && renderer_) return {};  // a rejoin: same job, keep everything

  auto definition = scene::load_scene(welcome.scene(), ".", image::decode_texture);
  if (!definition) {
    return Error{"cannot load the scene: " + definition.error() +
                 (welcome.scene().gltf().empty() ? "" : " (a node needs the master's scene file at the same path)")};
  }
  if (definition.value().content_sha256 != welcome.scene_sha256()) {
    return Error{"the scene file " + definition.value().source + " differs from the master's (sha256 " +
                 definition.value().content_sha256.substr(0, 12) + "… here, " + welcome.scene_sha256().substr(0, 12) +
                 "… on the master)"};
  }
  for (const auto& warning : definition.value().warnings) log_.warn("scene: {}", warning);

  auto geometry = config::projector_geometry(projector);
  if (!geometry) return Error{"projector '" + projector.id() + "': " + geometry.error()};
  auto view = render::ProjectorView::make(welcome.screen(), geometry.value(),
                                          render::parse_render_method(projector.rendering()));
  if (!view) return Error{"projector '" + projector.id() + "': " + view.error()};

  renderer_.reset();
  context_.reset();
  const int width = static_cast<int>(projector.width());
  const int height = static_cast<int>(projector.height());
  auto context =
      projector.output().kind() == "window"
          ? render::make_window_context("optique " + projector.id(), width, height,
                                        static_cast<int>(projector.output().monitor()), projector.output().fullscreen())
          : render::make_headless_context();
  if (!context) return Error{context.error()};
  context_ = std::move(context).value();
  auto renderer = render::SceneRenderer::create(definition.value().definition, view.value().render_width(),
                                                view.value().render_height());
  if (!renderer) return Error{renderer.error()};
  renderer_ = std::move(renderer).value();
  auto weights = blend_weights(welcome, geometry.value());
  if (!weights) return Error{"projector '" + projector.id() + "': " + weights.error()};
  focus_role_ = render::parse_focus_role(projector.content().role());
  render::OutputStage stage = view.value().output_stage(std::move(weights).value(), focus_role_);
  stage.focus.inset = welcome.depth_of_field().inset_radius() > 0.0;
  auto model = optics::ProjectorModel::from_config(projector);
  if (!model) return Error{"projector '" + projector.id() + "': " + model.error()};
  stage.projector = std::move(model).value();
  deep_signal_ = stage.projector.bits() > 8;
  depth_of_field_ = welcome.depth_of_field();
  if (auto output = renderer_->set_output(stage); !output) return Error{output.error()};
  view_ = std::move(view).value();
  terms_ = {};
  if (projector.content().role() == "lights") draw_share(welcome.lights());

  eye_ = geometry::parse_eye(projector.eye());
  const auto& viewer = welcome.viewer();
  head_right_ = glm::dvec3(viewer.head_right(0), viewer.head_right(1), viewer.head_right(2));
  eye_separation_ = viewer.eye_separation();
  near_ = viewer.near();
  far_ = viewer.far();
  // One draw now, seen from a metre in front of the region: drivers compile
  // shaders lazily, and the first frame should not pay for it.
  const glm::dvec3 warm_eye = view_->bounds().at(0.5, 0.5) + view_->bounds().normal();
  if (auto frustum = view_->frustum(warm_eye, near_, far_)) {
    renderer_->draw(scene::SceneState{}, 0.0, warm_eye, frustum.value());
  }
  if (!captures_) captures_.emplace(capture_folder_, log_);
  configured_for_ = key;
  log_.info("rendering {} with {} ({}), {}×{} px, {}", definition.value().source, context_->renderer_name(),
            context_->has_window() ? "window" : "headless", width, height,
            view_->method() == render::RenderMethod::two_pass
                ? "two passes (" + std::to_string(view_->render_width()) + "×" +
                      std::to_string(view_->render_height()) + " px, then warped)"
                : "single pass");
  return {};
}

void GlRenderer::draw_share(const wire::LightShare& share) {
  renderer_->set_lights(std::vector<std::uint32_t>(share.lights().begin(), share.lights().end()));
  terms_ = {share.ambient(), share.ambient()};
}

std::string GlRenderer::description() const {
  if (!context_) return "OpenGL (not configured)";
  return context_->renderer_name() + (context_->has_window() ? ", window" : ", headless");
}

void GlRenderer::render(const FrameInput& frame) {
  // A new share comes once, with the frame it starts at: taken even when this
  // frame shows nothing, so it is not lost.
  if (frame.lights != nullptr) draw_share(*frame.lights);
  const glm::dvec3 eye = geometry::eye_position(frame.state->eye_now, head_right_, eye_separation_, eye_);
  auto frustum = view_->frustum(eye, near_, far_);
  if (!frustum) {
    // The eye left the space in front of this screen: nothing of the scene can be
    // seen through it, so the projector shows black rather than a wrong picture.
    log_.debug("frame {}: {}", frame.frame_id, frustum.error());
    renderer_->draw_black();
  } else {
    if (focus_role_ != render::FocusRole::none && frame.focus != nullptr) {
      render::FocusFrame focus;
      focus.coc = optics::coc_from_window_depth(frame.focus->depth(), {depth_of_field_.near(), depth_of_field_.far()},
                                                near_, far_);
      focus.gaze = {frame.focus->gaze_x(), frame.focus->gaze_y()};
      focus.inset_radius = depth_of_field_.inset_radius();
      renderer_->set_focus(focus);
    }
    renderer_->draw(*frame.state, 0.0, eye, frustum.value(), terms_);
  }
  if (frame.capture) {
    captures_->submit(frame.frame_id, renderer_->read_linear(),
                      deep_signal_ ? image::ByteImage{} : renderer_->read_encoded(),
                      deep_signal_ ? renderer_->read_signal() : image::WordImage{});
  }
}

void GlRenderer::present() {
  context_->present(renderer_->output_framebuffer(), renderer_->width(), renderer_->height());
}

}  // namespace optique::node

namespace optique::node {

void GlRenderer::show_black() {
  if (!renderer_) return;  // not configured yet: nothing is on the projector
  renderer_->draw_black();
  present();
}

}  // namespace optique::node
