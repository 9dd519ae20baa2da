#pragma once
// Internal to render (scene_renderer.h is the public door): what the scene
// renderer's passes share. The scene on the GPU, the image it is drawn into,
// the output stage, and where the last frame's image before the output stage
// is (the linear image, or a frame between key frames) for the read-backs.

#include <span>

#include "render/fields.h"
#include "render/linear_target.h"
#include "render/output_pass.h"
#include "render/scene_pass.h"

namespace optique::render {

struct RendererParts {
  RendererParts(ScenePass scene_pass, LinearTarget target)
      : scene(std::move(scene_pass)),
        linear(std::move(target)),
        output(linear.format().width, linear.format().height),
        rendered_colour(linear.framebuffer()),
        rendered_depth(linear.framebuffer()) {}

  // The scene at `view` into the bound framebuffer, the linear image's size.
  void draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms,
            Objects which = Objects::all, const Motion* motion = nullptr);
  // The whole scene into the linear image, samples resolved: a frame before
  // its output stage.
  void draw_linear(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms);
  // A single-chip DLP projector's fields into the linear image, samples
  // resolved: each pass writes only its channels, so each colour shows the
  // scene at its field's moment. Seen from one place, what does not move is
  // drawn once for all (unless `still_once` is false).
  void draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes, const LightTerms& terms,
                   bool still_once);
  void encode() { output.encode(linear.colour(), linear.depth()); }  // the linear image
  void rendered_is_linear() { rendered_colour = rendered_depth = linear.framebuffer(); }

  ScenePass scene;
  LinearTarget linear;
  OutputPass output;
  GLuint rendered_colour;  // framebuffers the last frame's image and depth are read from
  GLuint rendered_depth;
};

}  // namespace optique::render
