#pragma once
// Draws a scene into its own framebuffers: linear light (RGBA32F colour, 32-bit
// float depth), then the output stage to the signal the projector is sent
// (render/output_pass.h). Needs a current OpenGL 4.5 context
// (render/gl_context.h); the same code runs headless and in a window.
//
// The public door to render's passes, each its own unit: the scene on the GPU
// (scene_pass), the image it is drawn into (linear_target), the output stage
// (output_pass), colour fields by the gather (gather_passes) and frame-rate
// up-conversion (up_conversion_passes). The last two exist only for
// projectors that use them.

#include <cstdint>
#include <memory>
#include <span>

#include "image/image.h"
#include "render/fields.h"
#include "render/gather_passes.h"
#include "render/output_pass.h"
#include "render/up_conversion_passes.h"
#include "render/viewpoint.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::render {

struct RendererParts;

// The depth buffer's format: 32-bit float by default; 24-bit fixed point to
// measure what a common hardware default does to depth order.
enum class DepthFormat { float32, fixed24 };

class SceneRenderer {
 public:
  // Uploads the scene's static content; draws `width` × `height` pixels, each
  // the average of `samples` (multisampling; 1: one at the pixel's centre).
  // Fails with the GL driver's message when a shader does not build or a
  // framebuffer is incomplete, or when the driver cannot draw that many samples.
  [[nodiscard]] static Result<std::unique_ptr<SceneRenderer>> create(const scene::SceneDefinition& scene, int width,
                                                                     int height,
                                                                     DepthFormat depth = DepthFormat::float32,
                                                                     int samples = 1);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Draws the scene at `view`, then the output stage; returns when the GPU is done.
  void draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms = {});
  // A single-chip DLP projector's frame: the scene drawn once per pass into one
  // image, each pass writing only its channels, so each colour shows the scene at
  // the moment its field is on screen; then the output stage, once. When every
  // pass sees the scene from the same place, what does not move is drawn once for
  // all of them (unless `still_once` is false: to measure what that saves).
  // Returns when the GPU is done.
  void draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes, const LightTerms& terms = {},
                   bool still_once = true);
  // Black everywhere (the projector shows nothing), encoded like a drawn frame.
  void draw_black();

  // An asset an application loaded (by its asset_id): its live instances are
  // drawn from now on. Fails with the driver's message, or when its content
  // is malformed.
  [[nodiscard]] Result<void> add_asset(const scene::SceneDefinition& asset);

  // Draws only these of the scene's point lights (indices; all by default), less
  // those the drawn state has switched off. Asserts that each exists.
  void set_lights(std::span<const std::uint32_t> lights);

  // The gather's passes (velocity target, tiles); only projectors that gather
  // have them. Fails with the driver's message.
  [[nodiscard]] Result<void> prepare_gather();
  [[nodiscard]] GatherPasses& gather();  // prepare_gather first
  // Up-conversion's passes with `slots` key frames (2, or up::kKeySlots where
  // they are drawn in bands); only projectors that up-convert have them.
  // Fails with the driver's message.
  [[nodiscard]] Result<void> prepare_up_conversion(int slots = 2);
  [[nodiscard]] UpConversionPasses& up_conversion();  // prepare_up_conversion first

  // The output stage (projector pixels): set it, and read what it made.
  [[nodiscard]] OutputPass& output();
  [[nodiscard]] const OutputPass& output() const;

  // The rendered image before the output stage (opaque: the alpha that carries
  // depth inside is read as 1), and its depth (window z in [0, 1]).
  [[nodiscard]] image::FloatImage read_rendered() const;
  [[nodiscard]] image::FloatImage read_depth() const;
  // The framebuffer read_rendered reads (its colour: a single-sampled texture).
  [[nodiscard]] unsigned rendered_framebuffer() const;

 private:
  explicit SceneRenderer(std::unique_ptr<RendererParts> parts);
  std::unique_ptr<RendererParts> parts_;
  std::unique_ptr<GatherPasses> gather_;
  std::unique_ptr<UpConversionPasses> up_;
};

}  // namespace optique::render
