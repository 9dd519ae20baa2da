#include "render/linear_target.h"

#include <string>

namespace optique::render {

Result<LinearTarget> LinearTarget::create(int width, int height, GLenum depth_format, int samples) {
  LinearTarget target;
  target.format_ = {width, height, depth_format, 1};
  // Linear light in 32-bit floats: stacked projectors add their shares, and half
  // floats (2⁻¹¹ relative) put highlights of 3 off by 2e-3 after the sum.
  // Depth in 32-bit float (or 24-bit fixed point).
  target.colour_ = glo::make_texture();
  const GLuint colour = target.colour_.get();
  glTextureStorage2D(colour, 1, GL_RGBA32F, width, height);
  // Bilinear for the two-pass warp; the single pass reads texels exactly.
  glTextureParameteri(colour, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(colour, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(colour, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(colour, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  target.depth_ = glo::make_storage(target.format_.depth, width, height);
  target.framebuffer_ = glo::make_framebuffer();
  glNamedFramebufferTexture(target.framebuffer_.get(), GL_COLOR_ATTACHMENT0, colour, 0);
  glNamedFramebufferTexture(target.framebuffer_.get(), GL_DEPTH_ATTACHMENT, target.depth_.get(), 0);
  const GLenum status = glCheckNamedFramebufferStatus(target.framebuffer_.get(), GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) return Error{"framebuffer incomplete (status " + std::to_string(status) + ")"};
  if (samples > 1) {
    GLint most = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &most);
    if (samples > most) {
      return Error{std::to_string(samples) + " samples per pixel asked for; this GL driver draws at most " +
                   std::to_string(most)};
    }
    target.format_.samples = samples;
    target.multisample_colour_ = glo::make_storage(GL_RGBA32F, width, height, samples);
    target.multisample_depth_ = glo::make_storage(target.format_.depth, width, height, samples);
    target.multisample_framebuffer_ = glo::make_framebuffer();
    const GLuint framebuffer = target.multisample_framebuffer_.get();
    glNamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0, target.multisample_colour_.get(), 0);
    glNamedFramebufferTexture(framebuffer, GL_DEPTH_ATTACHMENT, target.multisample_depth_.get(), 0);
    if (glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"this GL driver cannot draw " + std::to_string(samples) + " samples per pixel into RGBA32F"};
    }
  }
  return target;
}

GLuint LinearTarget::draw_framebuffer() const {
  return format_.samples > 1 ? multisample_framebuffer_.get() : framebuffer_.get();
}

void LinearTarget::begin(const glm::vec3& background, bool with_motion) {
  const GLuint framebuffer = draw_framebuffer();
  if (motion_attached_) {  // drawn into only by a gather
    static constexpr GLenum kBoth[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(framebuffer, with_motion ? 2 : 1, kBoth);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, format_.width, format_.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);  // thin objects (quads) are seen from both sides
  glClearColor(background.r, background.g, background.b, 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void LinearTarget::resolve() {
  if (format_.samples == 1) return;
  // Each pixel's samples averaged (linear light); depth from one sample, for the
  // passes that read it.
  const int w = format_.width;
  const int h = format_.height;
  glBlitNamedFramebuffer(multisample_framebuffer_.get(), framebuffer_.get(), 0, 0, w, h, 0, 0, w, h,
                         GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBlitNamedFramebuffer(multisample_framebuffer_.get(), framebuffer_.get(), 0, 0, w, h, 0, 0, w, h,
                         GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

Result<void> LinearTarget::attach_motion(GLuint texture) {
  glNamedFramebufferTexture(draw_framebuffer(), GL_COLOR_ATTACHMENT1, texture, 0);
  if (glCheckNamedFramebufferStatus(draw_framebuffer(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Error{"this GL driver cannot draw the scene's velocity beside its colour"};
  }
  motion_attached_ = true;
  return {};
}

void LinearTarget::keep_still_depth() {
  const int w = format_.width;
  const int h = format_.height;
  if (!still_depth_framebuffer_) {
    still_depth_ = glo::make_storage(format_.depth, w, h, format_.samples);
    still_depth_framebuffer_ = glo::make_framebuffer();
    glNamedFramebufferTexture(still_depth_framebuffer_.get(), GL_DEPTH_ATTACHMENT, still_depth_.get(), 0);
  }
  glBlitNamedFramebuffer(draw_framebuffer(), still_depth_framebuffer_.get(), 0, 0, w, h, 0, 0, w, h,
                         GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

void LinearTarget::bring_back_still_depth() {
  const int w = format_.width;
  const int h = format_.height;
  glBlitNamedFramebuffer(still_depth_framebuffer_.get(), draw_framebuffer(), 0, 0, w, h, 0, 0, w, h,
                         GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

}  // namespace optique::render
