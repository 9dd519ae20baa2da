#include "render/projector_pipeline.h"

#include <algorithm>
#include <cassert>
#include <vector>

#include "optics/blend.h"
#include "optics/defocus.h"

namespace optique::render {
namespace {

// This projector's share of the light where it overlaps the others of its blend
// group, zero where it is masked outside the screen's area.
image::FloatImage blend_weights(const config::ProjectorJob& job) {
  std::vector<geometry::ProjectorGeometry> group;
  std::vector<double> ramps;
  for (const config::Projector& member : job.installation.projectors) {
    group.push_back(member.geometry());
    ramps.push_back(member.blend_ramp);
  }
  const optics::BlendField field(group, job.screen().area(), ramps);
  return optics::blend_weights(field, group[job.projector], job.projector);
}

}  // namespace

ProjectorPipeline::ProjectorPipeline(ProjectorView view, std::unique_ptr<SceneRenderer> renderer,
                                     const config::ProjectorJob& job, optics::ProjectorModel model)
    : view_(std::move(view)),
      renderer_(std::move(renderer)),
      model_(std::move(model)),
      eye_(job.self().eye),
      viewer_(job.installation.viewer),
      focus_role_(focus_role(job.self().content.role)),
      depth_of_field_(job.installation.depth_of_field),
      color_fields_(job.self().color_fields) {}

Result<std::unique_ptr<ProjectorPipeline>> ProjectorPipeline::make(const config::ProjectorJob& job,
                                                                   const scene::SceneDefinition& scene,
                                                                   const PipelineOptions& options) {
  const config::Projector& self = job.self();
  // The config refuses these (config/projectors.cpp); a job built otherwise too.
  if (auto problem = config::up_conversion_with_fields(self.up_conversion, self.color_fields)) {
    return Error{"projector '" + self.id + "': " + problem->path + ": " + problem->message};
  }
  auto view = ProjectorView::make(job.screen(), self.geometry(), self.rendering, options.two_pass_pixels_per_metre);
  if (!view) return Error{"projector '" + self.id + "': " + view.error()};
  const int samples = options.samples > 0 ? options.samples : self.color_fields.sequential() ? kFieldSamples : 1;
  auto renderer =
      SceneRenderer::create(scene, view.value().render_width(), view.value().render_height(), options.depth, samples);
  if (!renderer) return Error{renderer.error()};
  const FocusRole role = focus_role(self.content.role);
  OutputStage stage = view.value().output_stage(options.blend ? blend_weights(job) : image::FloatImage{}, role);
  stage.focus.inset = job.installation.depth_of_field && job.installation.depth_of_field->inset_radius > 0.0;
  stage.projector = optics::ProjectorModel(self.response);
  if (auto output = renderer.value()->output().set(stage); !output) return Error{output.error()};
  if (self.color_fields.needs_velocity()) {
    if (auto gather = renderer.value()->prepare_gather(); !gather) {
      return Error{"projector '" + self.id + "': " + gather.error()};
    }
  }
  if (self.up_conversion.enabled() || self.color_fields.up_converts()) {
    const int slots = self.up_conversion.enabled() ? up::UpSchedule::slots_for(self.up_conversion) : 2;
    if (auto prepared = renderer.value()->prepare_up_conversion(slots); !prepared) {
      return Error{"projector '" + self.id + "': " + prepared.error()};
    }
  }
  std::unique_ptr<ProjectorPipeline> pipeline(
      new ProjectorPipeline(std::move(view).value(), std::move(renderer).value(), job, stage.projector));
  if (self.up_conversion.enabled()) pipeline->schedule_.emplace(self.up_conversion);
  if (self.content.role == config::ContentRole::lights) pipeline->set_share({});
  pipeline->still_once_ = options.still_once;
  return pipeline;
}

void ProjectorPipeline::set_share(const protocol::LightShare& share) {
  renderer_->set_lights(share.lights);
  terms_ = {share.ambient, share.ambient};
  // Kept key frames show the old share: the next frame is a key frame, so the
  // group's light changes on every node at once.
  if (schedule_) schedule_->forget();
}

void ProjectorPipeline::set_focus(const protocol::Focus& focus) {
  if (focus_role_ == FocusRole::none || !depth_of_field_) return;
  FocusFrame frame;
  frame.coc = optics::coc_from_window_depth(focus.depth, {depth_of_field_->near, depth_of_field_->far}, viewer_.near,
                                            viewer_.far);
  frame.gaze = focus.gaze;
  frame.inset_radius = depth_of_field_->inset_radius;
  renderer_->output().set_focus(frame);
}

glm::dvec3 ProjectorPipeline::eye(const scene::SceneState& state, double fraction) const {
  return viewer_.eye_in(state, fraction, eye_);
}

Result<Viewpoint> ProjectorPipeline::moment(const scene::SceneState& state, double fraction) const {
  // A still viewer is exactly where it stands at every moment: mix() would
  // round it differently per fraction, and the fields would no longer share one
  // view (what lets still objects be drawn once).
  const glm::dvec3 at = eye(state, fraction);
  auto frustum = view_.frustum(at, viewer_.near, viewer_.far);
  if (!frustum) return Error{frustum.error()};
  return seen_in_world(state, fraction, at, frustum.value());
}

Result<void> ProjectorPipeline::draw(const scene::SceneState& state, double fraction) {
  const auto seen = moment(state, fraction);
  if (!seen) {
    renderer_->draw_black();
    return Error{seen.error()};
  }
  renderer_->draw(state, seen.value(), terms_);
  return {};
}

Result<void> ProjectorPipeline::draw_frame(const scene::SceneState& state, const ImageDrawn& drawn,
                                           const DisplayFrame* display) {
  gather_report_ = {};
  if (schedule_) {
    const DisplayFrame next{next_frame_, {}};
    const DisplayFrame& frame = display ? *display : next;
    next_frame_ = frame.number + 1;
    auto result = draw_up_converted(state, frame);
    if (drawn) drawn(0);
    // The second image's fields are built from what the first's were, at their
    // own moments; black after a first that could not be seen.
    for (int image = 1; image < images(); ++image) {
      renderer_->output().hold();
      if (result) result = draw_fields_between(state, image);
      if (drawn) drawn(image);
    }
    return result;
  }
  Result<void> result;
  for (int image = 0; image < images(); ++image) {
    if (image > 0) renderer_->output().hold();  // shown while this one is drawn
    // A frame that cannot be seen is black in every image.
    if (result) result = draw_image(state, image);
    if (drawn) drawn(image);
  }
  return result;
}

unsigned ProjectorPipeline::image_framebuffer(int image) const {
  assert(image >= 0 && image < images() && images() <= 2);
  const OutputPass& output = renderer_->output();
  assert(images() == 1 || output.held_framebuffer() != 0);  // a frame was drawn
  return image + 1 < images() ? output.held_framebuffer() : output.framebuffer();
}

Result<void> ProjectorPipeline::draw_image(const scene::SceneState& state, int image) {
  if (!color_fields_.sequential()) {
    // Every image the same, drawn at the display time: the output holds it already.
    return image == 0 ? draw(state, 0.0) : Result<void>{};
  }
  if (color_fields_.gathers()) return draw_gathered(state, image);
  if (color_fields_.up_converts()) return draw_fields_up_converted(state, image);
  auto passes = field_passes(state, image);
  if (!passes) return Error{passes.error()};
  if (!color_fields_.blurs()) {
    renderer_->draw_fields(state, passes.value(), terms_, still_once_);
    return {};
  }
  // What is faster than the threshold gets motion blur over the image's time on
  // screen, from a render at its middle.
  const double share = 1.0 / images();
  auto blur = gather_frame(state, image, -0.5 + (image + 0.5) * share);
  if (!blur) {
    renderer_->draw_black();
    return Error{blur.error()};
  }
  blur.value().fields.clear();
  add(renderer_->gather().draw_fields_blurred(state, passes.value(), blur.value(), terms_, still_once_));
  return {};
}

Result<std::vector<FieldPass>> ProjectorPipeline::field_passes(const scene::SceneState& state, int image) {
  std::vector<FieldPass> passes;
  for (const config::ColorField& field : color_fields_.fields) {
    if (field.image != image) continue;
    auto pass = moment(state, field.offset);
    if (!pass) {
      renderer_->draw_black();
      return Error{pass.error()};
    }
    passes.push_back({pass.value(), field.channel == config::Channel::red, field.channel == config::Channel::green,
                      field.channel == config::Channel::blue});
  }
  return passes;
}

Result<void> ProjectorPipeline::draw_fields_up_converted(const scene::SceneState& state, int image) {
  // One render per frame, at the green fields' moment (as the gather): green is
  // shown as drawn; every other field, the second image's all, built from it.
  // With two images the render is halfway between their greens: every field is
  // built.
  std::optional<FieldPass> key;
  if (image == 0) {
    auto pass = moment(state, gather_moment());
    if (!pass) {
      renderer_->draw_black();
      return Error{pass.error()};
    }
    key = FieldPass{pass.value(), true, true, true};
  }
  auto passes = field_passes(state, image);
  if (!passes) return Error{passes.error()};
  renderer_->up_conversion().draw_fields_up_converted(state, key ? &*key : nullptr, passes.value(), terms_);
  return {};
}

double ProjectorPipeline::gather_moment() const {
  // Green carries most of what the eye sees as sharpness (and of PSNR_Y): the
  // scene is drawn at the green field's moment, so green is shown as drawn, not
  // resampled; with two images, halfway between their greens.
  double sum = 0.0;
  int greens = 0;
  for (const config::ColorField& field : color_fields_.fields) {
    if (field.channel != config::Channel::green) continue;
    sum += field.offset;
    ++greens;
  }
  assert(greens == images());  // every image has each channel (config/color_fields.h)
  return sum / greens;
}

Result<GatherFrame> ProjectorPipeline::gather_frame(const scene::SceneState& state, int image, double rendered) const {
  const auto seen = moment(state, rendered);
  const auto now = moment(state, 0.0);
  const auto next = moment(state, 1.0);
  for (const auto* m : {&seen, &now, &next}) {
    if (!*m) return Error{m->error()};
  }
  GatherFrame frame;
  frame.seen = seen.value();
  frame.view_projection_now = now.value().view_projection();
  frame.view_projection_next = next.value().view_projection();
  for (const config::ColorField& field : color_fields_.fields) {
    if (field.image != image) continue;
    frame.fields.push_back({field.channel == config::Channel::red, field.channel == config::Channel::green,
                            field.channel == config::Channel::blue, field.offset - rendered});
  }
  frame.settings.samples = color_fields_.gather_samples;
  frame.settings.velocity_threshold = color_fields_.velocity_threshold;
  // Above the threshold, motion blur over the time this image is on screen.
  const double share = 1.0 / images();
  frame.settings.frame_start = -0.5 + image * share - rendered;
  frame.settings.frame_end = -0.5 + (image + 1) * share - rendered;
  return frame;
}

void ProjectorPipeline::add(const GatherReport& report) {
  gather_report_.fastest = std::max(gather_report_.fastest, report.fastest);
  gather_report_.clamped = gather_report_.clamped || report.clamped;
  gather_report_.gathered_tiles += report.gathered_tiles;
}

Result<void> ProjectorPipeline::draw_gathered(const scene::SceneState& state, int image) {
  auto frame = gather_frame(state, image, gather_moment());
  if (!frame) {
    renderer_->draw_black();
    return Error{frame.error()};
  }
  // The second image's fields from the render the first made.
  GatherPasses& gather = renderer_->gather();
  add(image == 0 ? gather.draw_gathered(state, frame.value(), terms_)
                 : gather.gather_again(frame.value().fields, frame.value().settings));
  return {};
}

Result<void> ProjectorPipeline::draw_up_converted(const scene::SceneState& state, const DisplayFrame& display) {
  up::UpPlan plan = schedule_->plan(display.number, state, display.ahead);
  up_report_ = {};
  const auto black = [&](const std::string& why) -> Result<void> {
    // Nothing kept shows what the next frames need: they start over.
    schedule_->forget();
    up_report_ = {up::FrameKind::key, {}, std::nullopt, false, schedule_->ratio(), "not in front of the screen"};
    renderer_->draw_black();
    return Error{why};
  };
  if (plan.draw_key && plan.ahead_frame && !moment(*plan.key_state, 0.0)) {
    // The key frame ahead cannot be seen (the eye will have left the space in
    // front of this screen): this frame is drawn on its own, and so on.
    schedule_->forget();
    plan = schedule_->plan(display.number, state, display.ahead);
  }
  up_report_.kind = plan.kind();
  up_report_.why = plan.why;
  up_report_.drew_key_ahead = plan.ahead_frame.has_value();
  // The adaptive ratio's check: the frame between from kept key
  // plan.check_slot at `key`'s moment, against what was just drawn for it (or
  // kept key `against`).
  UpConversionPasses& up_passes = renderer_->up_conversion();
  const auto check = [&](const scene::SceneState& key, const Viewpoint& seen, std::optional<int> against) {
    if (!plan.check_slot) return;
    up::BetweenFrame from;
    from.method = schedule_->settings().method;
    from.first = *plan.check_slot;
    up_report_.checked_psnr = up_passes.check_between(key, seen, from, terms_, against);
    schedule_->checked(*up_report_.checked_psnr);
  };
  if (plan.band) {  // first: it draws through the image the frame's own then replaces
    const up::UpPlan::Band& band = *plan.band;
    const auto seen = moment(*band.state, 0.0);
    if (!seen) {
      schedule_->drop_band();  // its moment cannot be seen from here: another is begun later
    } else {
      up_passes.draw_key_band(*band.state, seen.value(), terms_, band.slot, band.index, band.count, band.bands);
      if (band.last()) check(*band.state, seen.value(), band.slot);
    }
  }
  if (plan.draw_key) {
    const scene::SceneState* key = plan.key_state;  // this frame's, or one sent ahead
    const auto seen = moment(*key, 0.0);
    if (!seen) return black(seen.error());
    renderer_->draw(*key, seen.value(), terms_);
    check(*key, seen.value(), std::nullopt);
    up_passes.keep_key(plan.key_slot, {*key, 0.0, seen.value().view_projection()});
  }
  up_report_.ratio = schedule_->ratio();
  if (color_fields_.sequential()) {
    fields_from_ = plan.frame;
    if (!plan.between) {  // a key frame: its own fields from it alone
      fields_from_ = {};
      fields_from_.method = schedule_->settings().method;
      fields_from_.first = plan.shown_slot ? *plan.shown_slot : plan.key_slot;
    }
    fields_between_ = plan.between;
    return draw_fields_between(state, 0);
  }
  if (plan.shown_slot) up_passes.show_key(*plan.shown_slot);
  if (!plan.between) return {};
  const auto seen = moment(state, 0.0);
  if (!seen) return black(seen.error());
  up_report_.between = up_passes.draw_between(state, seen.value(), plan.frame, terms_);
  return {};
}

Result<void> ProjectorPipeline::draw_fields_between(const scene::SceneState& state, int image) {
  auto passes = field_passes(state, image);
  if (!passes) return Error{passes.error()};  // drawn black
  const up::BetweenReport report =
      renderer_->up_conversion().draw_fields_between(state, passes.value(), fields_from_, terms_);
  // The frame's report: the image that left the most unseen.
  if (fields_between_ && (image == 0 || report.unseen_share > up_report_.between.unseen_share)) {
    up_report_.between = report;
  }
  return {};
}

void ProjectorPipeline::warm_up(const scene::SceneState& state) {
  const glm::dvec3 in_front = view_.bounds().at(0.5, 0.5) + view_.bounds().normal();
  auto frustum = view_.frustum(in_front, viewer_.near, viewer_.far);
  if (!frustum) return;
  const Viewpoint seen{0.0, in_front, frustum.value()};
  renderer_->draw(state, seen);
  if (schedule_) {  // the motion fields, each resolve and the check
    UpConversionPasses& up_passes = renderer_->up_conversion();
    for (int slot = 0; slot < schedule_->slots(); ++slot) {
      up_passes.keep_key(slot, {state, 0.0, seen.view_projection()});
    }
    (void)up_passes.check_between(state, seen, {}, terms_);
    up::BetweenFrame frame;
    frame.method = schedule_->settings().method;
    for (bool two : {false, true}) {
      frame.two_keys = two;
      (void)up_passes.draw_between(state, seen, frame, terms_);
    }
  }
  if (color_fields_.up_converts()) {  // one field at the render's moment, one built from it
    const FieldPass key{seen, true, true, true};
    FieldPass other = key;
    other.view.fraction = 0.5;
    other.green = other.blue = false;
    renderer_->up_conversion().draw_fields_up_converted(state, &key, {&other, 1});
  }
  if (color_fields_.needs_velocity()) {
    // The velocity program and the tile passes too (the field pass itself
    // first runs when something moves).
    GatherFrame frame;
    frame.seen = seen;
    frame.view_projection_now = seen.view_projection();
    frame.view_projection_next = frame.view_projection_now;
    frame.fields.push_back({true, true, true, 0.0});
    (void)renderer_->gather().draw_gathered(state, frame);
  }
}

}  // namespace optique::render
