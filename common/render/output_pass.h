#pragma once
// The output stage: what lies between the rendered image (linear light) and the
// projector. A two-pass projector warps the viewer's image to its own pixels;
// every projector multiplies by its blend weights (zero where it is masked),
// a focus/defocus pair takes its share, and the projector's response, bit
// depth, black level and brightness (optics/projector_model.h) turn light into
// the signal it is sent. Needs a current OpenGL 4.5 context.

#include <optional>

#include <epoxy/gl.h>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>

#include "image/image.h"
#include "optics/defocus.h"
#include "optics/projector_model.h"
#include "render/gl_objects.h"
#include "util/result.h"

namespace optique::render {

// A focus/defocus pair's share of the image: the focus projector shows (1 − c_r)
// of the light, the defocus one c_r (or, in the inset variant, inside and outside
// a disc around the gaze point).
enum class FocusRole { none, focus, defocus };

struct FocusShare {
  FocusRole role = FocusRole::none;
  bool inset = false;  // share by a disc around the gaze point instead of c_r
  // Single pass: A and the depth scale, to undo what they did to window depth.
  glm::dmat3 user_to_projector{1.0};
  double depth_scale = 1.0;
  // Output pixels (GL fragment coordinates, rows up) → screen metres, for the inset.
  glm::dmat3 fragment_to_screen{1.0};
  double screen_metres_per_pixel = 1e-3;  // the inset's edge is this soft
};

// What changes per frame for a focus/defocus projector.
struct FocusFrame {
  optics::CocFromWindowDepth coc;  // from the frame's focal depth
  glm::dvec2 gaze{0.0};            // screen metres
  double inset_radius = 0.0;
};

// The default does nothing: the projector shows the rendered image as it is.
struct OutputStage {
  int width = 0;  // projector pixels; 0: the rendered image's size
  int height = 0;
  // Two-pass only: projector NDC → user NDC (A⁻¹); the rendered image spans
  // user NDC [−1, 1]² and is sampled bilinearly.
  std::optional<glm::dmat3> projector_to_user;
  image::FloatImage weights;         // 1 channel, width × height, top row first; empty: 1 everywhere
  optics::ProjectorModel projector;  // response, bit depth, black level, brightness
  FocusShare focus;
};

class OutputPass {
 public:
  // For rendered images of this size; set() before the first encode().
  OutputPass(int rendered_width, int rendered_height)
      : rendered_width_(rendered_width), rendered_height_(rendered_height) {}

  // Builds the pass for `stage`; fails with the driver's message, or when the
  // weights do not match the output size. The old one stays until it is built.
  [[nodiscard]] Result<void> set(const OutputStage& stage);
  // The focal depth and gaze of the frame to come (focus/defocus projectors).
  void set_focus(const FocusFrame& frame);
  // `colour` (a rendered image, linear) and its `depth` through the stage into
  // framebuffer(); returns when the GPU is done.
  void encode(GLuint colour, GLuint depth);
  // Copies the output aside, to be shown while the next image is drawn into it
  // (a projector that shows two images per frame); GL orders the copy before
  // whatever is drawn next.
  void hold();
  [[nodiscard]] GLuint held_framebuffer() const { return held_framebuffer_.get(); }  // 0 before the first hold
  [[nodiscard]] GLuint framebuffer() const { return encoded_framebuffer_.get(); }    // the signal, for a window blit

  // RGBA: the light the projector emits for the signal (its model, on the CPU).
  [[nodiscard]] image::FloatImage read_linear() const;
  [[nodiscard]] image::ByteImage read_encoded() const;  // RGBA8, the signal (8 bits deep at most)
  [[nodiscard]] image::WordImage read_signal() const;   // RGBA16: the signal at any depth, ·65535
  [[nodiscard]] int width() const { return width_; }    // projector pixels
  [[nodiscard]] int height() const { return height_; }

 private:
  int rendered_width_ = 0;
  int rendered_height_ = 0;
  int width_ = 0;
  int height_ = 0;
  optics::ProjectorModel projector_;
  glo::Program program_;
  struct {
    GLint coc, inset_disc;
  } focus_uniforms_{};
  glo::VertexArray empty_vertex_array_;
  glo::Framebuffer encoded_framebuffer_;
  glo::Texture encoded_colour_;
  glo::Framebuffer held_framebuffer_;  // hold(): made when first needed
  glo::Texture held_colour_;
  glo::Texture weights_;
  glo::Texture response_table_;
};

}  // namespace optique::render
