#include "render/box_reduce.h"

#include <string>

#include "render/shaders.h"

namespace optique::render {

Result<BoxReduce> BoxReduce::make(int width, int height, int factor) {
  if (width < 1 || height < 1 || factor < 1) {
    return Error{"a box reduction needs a size and a factor of at least 1, not " + std::to_string(width) + "×" +
                 std::to_string(height) + " by " + std::to_string(factor)};
  }
  auto program = glo::link_program(shaders::fullscreen_vert,
                                   std::string("#version 450 core\n") + std::string(shaders::box_reduce_frag));
  if (!program) return Error{"the box reduction's shaders: " + program.error()};
  BoxReduce r;
  r.width_ = width;
  r.height_ = height;
  r.factor_ = factor;
  r.program_ = std::move(program).value();
  r.source_location_ = glGetUniformLocation(r.program_.get(), "source");
  r.factor_location_ = glGetUniformLocation(r.program_.get(), "factor");
  r.reduced_ = glo::make_texture();
  glTextureStorage2D(r.reduced_.get(), 1, GL_RGBA32F, width, height);
  r.framebuffer_ = glo::make_framebuffer();
  glNamedFramebufferTexture(r.framebuffer_.get(), GL_COLOR_ATTACHMENT0, r.reduced_.get(), 0);
  if (glCheckNamedFramebufferStatus(r.framebuffer_.get(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Error{"the box reduction's framebuffer is not complete"};
  }
  r.empty_vertex_array_ = glo::make_vertex_array();
  return r;
}

Result<image::FloatImage> BoxReduce::read(unsigned framebuffer) const {
  GLint type = GL_NONE;
  GLint name = 0;
  glGetNamedFramebufferAttachmentParameteriv(framebuffer, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE,
                                             &type);
  glGetNamedFramebufferAttachmentParameteriv(framebuffer, GL_COLOR_ATTACHMENT0, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_NAME,
                                             &name);
  if (type != GL_TEXTURE || name == 0) return Error{"a box reduction reads a texture, and the framebuffer has none"};
  const auto texture = static_cast<GLuint>(name);
  GLint target = GL_NONE;
  glGetTextureParameteriv(texture, GL_TEXTURE_TARGET, &target);
  if (target != GL_TEXTURE_2D) return Error{"a box reduction reads a 2D texture, not a layered or multisampled one"};
  GLint samples = 0;
  GLint width = 0;
  GLint height = 0;
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_SAMPLES, &samples);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_WIDTH, &width);
  glGetTextureLevelParameteriv(texture, 0, GL_TEXTURE_HEIGHT, &height);
  if (samples > 1)
    return Error{"a box reduction reads a single-sampled texture, not one of " + std::to_string(samples)};
  if (width != width_ * factor_ || height != height_ * factor_) {
    return Error{"a box reduction by " + std::to_string(factor_) + " to " + std::to_string(width_) + "×" +
                 std::to_string(height_) + " was given " + std::to_string(width) + "×" + std::to_string(height)};
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glUseProgram(program_.get());
  glBindTextureUnit(0, texture);
  glUniform1i(source_location_, 0);
  glUniform1i(factor_location_, factor_);
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);

  return glo::read_float(framebuffer_.get(), width_, height_, GL_RGBA, 4);
}

}  // namespace optique::render
