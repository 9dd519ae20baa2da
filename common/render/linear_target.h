#pragma once
// Internal to render (scene_renderer.h is the public door): the image the scene
// is drawn into. Linear light in RGBA32F with its depth; drawn multisampled and
// averaged into those when a pixel has several samples; and, for colour fields
// seen from one place, the still objects' depth kept aside.

#include <epoxy/gl.h>
#include <glm/vec3.hpp>

#include "render/gl_objects.h"
#include "util/result.h"

namespace optique::render {

struct LinearFormat {
  int width = 0;
  int height = 0;
  GLenum depth = GL_DEPTH_COMPONENT32F;  // or GL_DEPTH_COMPONENT24
  int samples = 1;                       // per pixel
};

class LinearTarget {
 public:
  // Depth in `depth_format` (GL_DEPTH_COMPONENT32F or 24). Fails when the
  // driver cannot draw that many samples.
  [[nodiscard]] static Result<LinearTarget> create(int width, int height, GLenum depth_format, int samples);
  [[nodiscard]] const LinearFormat& format() const { return format_; }

  // Binds what the scene is drawn into and clears it to `background`; with
  // `with_motion`, the motion target attached beside the colour is drawn too.
  void begin(const glm::vec3& background, bool with_motion = false);
  void resolve();  // multisampled: the samples averaged into colour() and depth()
  // A second colour target (the gather's velocity) drawn only by begin(…, true).
  [[nodiscard]] Result<void> attach_motion(GLuint texture);
  void keep_still_depth();        // the depth drawn so far, aside
  void bring_back_still_depth();  // and back

  [[nodiscard]] GLuint framebuffer() const { return framebuffer_.get(); }  // colour() and depth()
  [[nodiscard]] GLuint draw_framebuffer() const;  // what begin() binds: multisampled or framebuffer()
  [[nodiscard]] GLuint colour() const { return colour_.get(); }
  [[nodiscard]] GLuint depth() const { return depth_.get(); }
  [[nodiscard]] GLuint multisample_depth() const { return multisample_depth_.get(); }  // 0 with one sample

 private:
  LinearTarget() = default;
  LinearFormat format_;
  glo::Framebuffer framebuffer_;
  glo::Texture colour_;
  glo::Texture depth_;
  glo::Framebuffer multisample_framebuffer_;
  glo::Texture multisample_colour_;
  glo::Texture multisample_depth_;
  bool motion_attached_ = false;
  glo::Framebuffer still_depth_framebuffer_;  // made when first needed
  glo::Texture still_depth_;
};

}  // namespace optique::render
