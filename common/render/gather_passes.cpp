#include "render/gather_passes.h"

#include "render/field_gather.h"
#include "render/renderer_parts.h"

namespace optique::render {

Result<std::unique_ptr<GatherPasses>> GatherPasses::create(RendererParts& parts) {
  if (auto program = parts.scene.prepare_velocity(); !program) return Error{program.error()};
  const LinearFormat& format = parts.linear.format();
  auto gather = FieldGather::create(format.width, format.height, format.samples);
  if (!gather) return Error{gather.error()};
  if (auto attached = parts.linear.attach_motion(gather.value()->motion_target()); !attached) {
    return Error{attached.error()};
  }
  return std::unique_ptr<GatherPasses>(new GatherPasses(parts, std::move(gather).value()));
}

GatherPasses::GatherPasses(RendererParts& parts, std::unique_ptr<FieldGather> gather)
    : parts_(parts), gather_(std::move(gather)) {}
GatherPasses::~GatherPasses() = default;

GatherReport GatherPasses::draw_gathered(const scene::SceneState& state, const GatherFrame& frame,
                                         const LightTerms& terms) {
  draw_with_motion(state, frame, terms);
  return gather_again(frame.fields, frame.settings);
}

GatherReport GatherPasses::gather_again(std::span<const GatherField> fields, const GatherSettings& settings) {
  const GatherReport report = gather_->gather(parts_.linear.colour(), fields, settings);
  parts_.output.encode(gather_->output(), parts_.linear.depth());
  return report;
}

GatherReport GatherPasses::draw_fields_blurred(const scene::SceneState& state, std::span<const FieldPass> passes,
                                               const GatherFrame& blur, const LightTerms& terms, bool still_once) {
  parts_.draw_fields(state, passes, terms, still_once);
  // The fields aside; the scene once more, with its velocity, for the blur of
  // what is too fast to follow, laid over them.
  gather_->keep(parts_.linear.colour());
  draw_with_motion(state, blur, terms);
  return gather_again({}, blur.settings);  // no fields: the blur alone, over what keep() put aside
}

void GatherPasses::draw_with_motion(const scene::SceneState& state, const GatherFrame& frame, const LightTerms& terms) {
  parts_.rendered_is_linear();
  parts_.linear.begin(parts_.scene.background(), true);
  FieldGather::clear_motion(parts_.linear.draw_framebuffer());  // after: begin cleared it to the background
  const Motion motion{{{&state, 0.0, frame.view_projection_now}, {&state, 1.0, frame.view_projection_next}}};
  parts_.draw(state, frame.seen, terms, Objects::all, &motion);
  parts_.linear.resolve();
  gather_->measure();
}

}  // namespace optique::render
