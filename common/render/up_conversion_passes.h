#pragma once
// Frame-rate up-conversion (render/up_converter.h): key frames kept, frames
// between them built from their motion field, and colour fields built from
// key frames. A SceneRenderer's passes for projectors that up-convert, made by
// SceneRenderer::prepare_up_conversion.

#include <memory>
#include <optional>
#include <span>

#include "render/fields.h"
#include "render/viewpoint.h"
#include "scene/state.h"
#include "up/between.h"
#include "util/result.h"

namespace optique::render {

struct RendererParts;
class UpConverter;

class UpConversionPasses {
 public:
  ~UpConversionPasses();
  UpConversionPasses(const UpConversionPasses&) = delete;
  UpConversionPasses& operator=(const UpConversionPasses&) = delete;

  // The image the last SceneRenderer::draw made kept as key frame `slot`,
  // drawn as `view` says.
  void keep_key(int slot, up::KeyView view);
  // Bands `index` … `index + bands − 1` of `count` (rows, from the bottom) of a
  // key frame drawn as SceneRenderer::draw would, at `state` from `view`, into
  // key slot `slot`: the rest of the slot stays. Drawn through the linear
  // image: before the frame's own (draw_between, show_key); nothing is shown.
  void draw_key_band(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms, int slot,
                     int index, int count, int bands = 1);
  // A frame between key frames, at `state` from `view`: the motion field drawn
  // with the scene's geometry, each pixel from the kept key frames where its
  // surface was, what none saw shaded anew (as `frame` says); or their
  // average. Then the output stage. Returns when the GPU is done.
  up::BetweenReport draw_between(const scene::SceneState& state, const Viewpoint& view, const up::BetweenFrame& frame,
                                 const LightTerms& terms = {});
  // The frame between that `frame` would build for the state the last draw
  // showed, weighed against what that draw made (or against kept key
  // `against_slot`, drawn for `state`): PSNR_Y (dB, the up-conversion paper's;
  // +infinity when equal). The output stays the last frame's.
  [[nodiscard]] double check_between(const scene::SceneState& state, const Viewpoint& view,
                                     const up::BetweenFrame& frame, const LightTerms& terms = {},
                                     std::optional<int> against_slot = {});
  // Key `slot` as it was kept, through the output stage (a key frame drawn
  // ahead, shown at its own moment).
  void show_key(int slot);
  // Colour fields by up-conversion: with `key`, the scene drawn at its moment
  // and kept as key frame 0; then each of `passes` (a field at its own moment)
  // built from key frame 0 as a frame between (what it did not see shaded
  // anew) into its channels of the image, except those at the key's own moment,
  // which show it as drawn. Then the output stage.
  void draw_fields_up_converted(const scene::SceneState& state, const FieldPass* key, std::span<const FieldPass> passes,
                                const LightTerms& terms = {});
  // Colour fields of a frame that frame-rate up-conversion builds: each of
  // `passes` built from the kept key frames as `from` says (two weighed by the
  // pass's own moment), into its channels of the image. Then the output stage.
  // The largest share of a field's pixels that no key frame saw.
  up::BetweenReport draw_fields_between(const scene::SceneState& state, std::span<const FieldPass> passes,
                                        const up::BetweenFrame& from, const LightTerms& terms = {});

 private:
  friend class SceneRenderer;
  // The motion field's programs, the key slots (`slots`: 2, or up::kKeySlots
  // where they are drawn in bands), targets and passes; fails with the
  // driver's message.
  [[nodiscard]] static Result<std::unique_ptr<UpConversionPasses>> create(RendererParts& parts, int slots);
  UpConversionPasses(RendererParts& parts, std::unique_ptr<UpConverter> converter);
  // A frame between key frames into the up-converter's output (draw_between
  // without the output stage).
  up::BetweenReport build_between(const scene::SceneState& state, const Viewpoint& view, const up::BetweenFrame& frame,
                                  const LightTerms& terms);
  // Each of `passes` but `shown` (at the image's own moment: left as drawn)
  // built as `from` says into its channels of the linear image; then encoded.
  up::BetweenReport build_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                 const up::BetweenFrame& from, const LightTerms& terms, const FieldPass* shown);

  RendererParts& parts_;
  std::unique_ptr<UpConverter> converter_;
};

}  // namespace optique::render
