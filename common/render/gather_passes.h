#pragma once
// Colour fields by the gather method, and the motion blur of per-field
// rendering (render/field_gather.h): a SceneRenderer's passes for projectors
// that gather, made by SceneRenderer::prepare_gather.

#include <memory>
#include <span>

#include "render/fields.h"
#include "render/viewpoint.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::render {

struct RendererParts;
class FieldGather;

class GatherPasses {
 public:
  ~GatherPasses();
  GatherPasses(const GatherPasses&) = delete;
  GatherPasses& operator=(const GatherPasses&) = delete;

  // The scene drawn once at `frame.seen`'s moment with its velocity, and
  // `frame`'s fields gathered from it; then the output stage. Returns when the
  // GPU is done, with what the gather found.
  [[nodiscard]] GatherReport draw_gathered(const scene::SceneState& state, const GatherFrame& frame,
                                           const LightTerms& terms = {});
  // Other fields from the render draw_gathered made last (the second image of a
  // stereo projector used as mono), into the output.
  [[nodiscard]] GatherReport gather_again(std::span<const GatherField> fields, const GatherSettings& settings);
  // A DLP frame drawn per field (SceneRenderer::draw_fields), and the scene
  // once more at `blur.seen`'s moment with its velocity: pixels faster than
  // the velocity threshold (set; its fields empty) get motion blur over the
  // frame window instead of their fields. Then the output stage.
  [[nodiscard]] GatherReport draw_fields_blurred(const scene::SceneState& state, std::span<const FieldPass> passes,
                                                 const GatherFrame& blur, const LightTerms& terms = {},
                                                 bool still_once = true);

 private:
  friend class SceneRenderer;
  // The velocity program and target, tiles and passes; fails with the driver's message.
  [[nodiscard]] static Result<std::unique_ptr<GatherPasses>> create(RendererParts& parts);
  GatherPasses(RendererParts& parts, std::unique_ptr<FieldGather> gather);
  // The scene at `frame.seen`'s moment with its velocity, resolved, and the
  // gather's tiles measured: what a gather or a blur starts from.
  void draw_with_motion(const scene::SceneState& state, const GatherFrame& frame, const LightTerms& terms);

  RendererParts& parts_;
  std::unique_ptr<FieldGather> gather_;
};

}  // namespace optique::render
