#include "render/up_conversion_passes.h"

#include <algorithm>
#include <cassert>

#include "render/renderer_parts.h"
#include "render/up_converter.h"

namespace optique::render {

Result<std::unique_ptr<UpConversionPasses>> UpConversionPasses::create(RendererParts& parts, int slots) {
  if (auto programs = parts.scene.prepare_motion_field(); !programs) return Error{programs.error()};
  const LinearFormat& format = parts.linear.format();
  auto converter = UpConverter::create(format.width, format.height, format.depth, slots, format.samples);
  if (!converter) return Error{converter.error()};
  return std::unique_ptr<UpConversionPasses>(new UpConversionPasses(parts, std::move(converter).value()));
}

UpConversionPasses::UpConversionPasses(RendererParts& parts, std::unique_ptr<UpConverter> converter)
    : parts_(parts), converter_(std::move(converter)) {}
UpConversionPasses::~UpConversionPasses() = default;

void UpConversionPasses::keep_key(int slot, up::KeyView view) {
  const LinearTarget& linear = parts_.linear;
  converter_->keys().keep(slot, linear.colour(), linear.depth(), linear.multisample_depth(), std::move(view));
}

up::BetweenReport UpConversionPasses::build_between(const scene::SceneState& state, const Viewpoint& view,
                                                    const up::BetweenFrame& frame, const LightTerms& terms) {
  UpConverter& converter = *converter_;
  const bool motion = frame.method == up::BetweenMethod::motion;
  if (motion) {
    converter.begin_motion_field(frame.two_keys);
    const up::KeyView& first = converter.keys().view(frame.first);
    const up::KeyView& second = converter.keys().view(frame.two_keys ? frame.second : frame.first);
    const Motion field{{{&first.state, first.fraction, first.view_projection},
                        {&second.state, second.fraction, second.view_projection}},
                       frame.two_keys ? 2 : 1};
    parts_.draw(state, view, terms, Objects::all, &field);
  }
  const up::BetweenReport report = converter.resolve(frame, parts_.scene.background());
  if (motion && frame.shade_unseen && report.unseen_pixels > 0) {
    converter.begin_shade_unseen();
    parts_.draw(state, view, terms);
    converter.end_shade_unseen();
  }
  converter.finish();
  return report;
}

up::BetweenReport UpConversionPasses::draw_between(const scene::SceneState& state, const Viewpoint& view,
                                                   const up::BetweenFrame& frame, const LightTerms& terms) {
  const up::BetweenReport report = build_between(state, view, frame, terms);
  const UpConverter& converter = *converter_;
  const LinearTarget& linear = parts_.linear;
  const bool motion = frame.method == up::BetweenMethod::motion;
  // The average has no depth of its own: the first key frame's (the linear
  // depth may hold bands of a key frame being drawn).
  if (!motion) converter.keys().restore_depth(frame.first, linear.depth());
  parts_.rendered_colour = converter.output_framebuffer();
  parts_.rendered_depth = motion ? converter.output_framebuffer() : linear.framebuffer();
  parts_.output.encode(converter.output(), motion ? converter.depth() : linear.depth());
  return report;
}

double UpConversionPasses::check_between(const scene::SceneState& state, const Viewpoint& view,
                                         const up::BetweenFrame& frame, const LightTerms& terms,
                                         std::optional<int> against_slot) {
  (void)build_between(state, view, frame, terms);
  UpConverter& converter = *converter_;
  return converter.psnr_y_against(against_slot ? converter.keys().colour(*against_slot) : parts_.linear.colour());
}

void UpConversionPasses::draw_key_band(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms,
                                       int slot, int index, int count, int bands) {
  assert(count >= 1 && index >= 0 && bands >= 1 && index + bands <= count);
  const LinearTarget& linear = parts_.linear;
  const int width = linear.format().width;
  const int height = linear.format().height;
  const int first_row = height * index / count;
  const int rows = height * (index + bands) / count - first_row;
  // The scissor bounds the clear, the fragments and the multisample resolve;
  // the geometry is processed whole each band.
  glEnable(GL_SCISSOR_TEST);
  glScissor(0, first_row, width, rows);
  parts_.draw_linear(state, view, terms);
  glDisable(GL_SCISSOR_TEST);
  converter_->keys().keep_rows(slot, linear.colour(), linear.depth(), linear.multisample_depth(),
                               {state, view.fraction, view.view_projection()}, first_row, rows);
}

void UpConversionPasses::draw_fields_up_converted(const scene::SceneState& state, const FieldPass* key,
                                                  std::span<const FieldPass> passes, const LightTerms& terms) {
  if (key != nullptr) {
    parts_.draw_linear(state, key->view, terms);
    keep_key(0, {state, key->view.fraction, key->view.view_projection()});
  }
  up::BetweenFrame from;
  from.first = 0;
  (void)build_fields(state, passes, from, terms, key);
}

up::BetweenReport UpConversionPasses::draw_fields_between(const scene::SceneState& state,
                                                          std::span<const FieldPass> passes,
                                                          const up::BetweenFrame& from, const LightTerms& terms) {
  return build_fields(state, passes, from, terms, nullptr);
}

up::BetweenReport UpConversionPasses::build_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                                   const up::BetweenFrame& from, const LightTerms& terms,
                                                   const FieldPass* shown) {
  const auto at_shown = [&](const FieldPass& pass) {
    return shown != nullptr && pass.view.fraction == shown->view.fraction && pass.view.same_place(shown->view);
  };
  up::BetweenReport most;
  for (const FieldPass& pass : passes) {
    if (at_shown(pass)) continue;  // shown as drawn
    up::BetweenFrame frame = from;
    if (frame.two_keys) {
      frame.toward_second = std::clamp(from.toward_second + pass.view.fraction * from.per_frame, 0.0, 1.0);
    }
    const up::BetweenReport report = build_between(state, pass.view, frame, terms);
    if (report.unseen_share >= most.unseen_share) most = report;
    converter_->write_channels(parts_.linear.framebuffer(), pass.red, pass.green, pass.blue);
  }
  parts_.rendered_is_linear();
  parts_.encode();
  return most;
}

void UpConversionPasses::show_key(int slot) {
  // Back where a draw leaves an image: SceneRenderer::read_rendered and
  // read_depth find it.
  converter_->keys().restore(slot, parts_.linear.colour(), parts_.linear.depth());
  parts_.rendered_is_linear();
  parts_.encode();
}

}  // namespace optique::render
