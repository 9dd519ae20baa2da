#pragma once
// Draws a scene into its own framebuffers: linear light (RGBA16F colour, 32-bit
// float depth), then an encoding pass to what the projector is sent (8-bit, sRGB
// response). Needs a current OpenGL 4.5 context (render/gl_context.h); the same
// code runs headless and in a window.

#include <memory>

#include "image/image.h"
#include "render/projection.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::render {

// Which light terms this renderer draws (a node of a stacked group may carry only
// some of them).
struct LightTerms {
  bool ambient = true;
  bool emissive = true;
};

class SceneRenderer {
 public:
  // Uploads the scene's static content. Fails with the GL driver's message when
  // a shader does not build or a framebuffer is incomplete.
  [[nodiscard]] static Result<std::unique_ptr<SceneRenderer>> create(const scene::SceneDefinition& scene, int width,
                                                                     int height);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Draws the scene with animated objects at `fraction` between their two frame
  // poses, seen from `eye` through `frustum`; returns when the GPU is done.
  void draw(const scene::SceneState& state, double fraction, const glm::dvec3& eye, const Frustum& frustum,
            const LightTerms& terms = {});

  // Black everywhere (the projector shows nothing), encoded like a drawn frame.
  void draw_black();

  [[nodiscard]] image::FloatImage read_linear() const;  // RGBA, linear light
  [[nodiscard]] image::ByteImage read_encoded() const;  // RGBA8, as sent to the projector
  [[nodiscard]] unsigned output_framebuffer() const;    // the encoded image, for a window blit
  [[nodiscard]] int width() const;
  [[nodiscard]] int height() const;

 private:
  struct Gl;
  explicit SceneRenderer(std::unique_ptr<Gl> gl);
  void encode();
  std::unique_ptr<Gl> gl_;
};

}  // namespace optique::render
