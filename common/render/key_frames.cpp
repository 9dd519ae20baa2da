#include "render/key_frames.h"

#include <cassert>
#include <string>

#include "render/shaders.h"

namespace optique::render {
namespace {

void copy(GLuint from, GLuint to, int width, int height, int first_row = 0) {
  glCopyImageSubData(from, GL_TEXTURE_2D, 0, 0, first_row, 0, to, GL_TEXTURE_2D, 0, 0, first_row, 0, width, height, 1);
}

}  // namespace

Result<KeyFrames> KeyFrames::create(int width, int height, GLenum depth_format, int slots, int samples) {
  assert(slots >= 2 && slots <= up::kKeySlots);
  KeyFrames keys;
  keys.width_ = width;
  keys.height_ = height;
  keys.slots_ = slots;
  keys.samples_ = samples;
  for (int k = 0; k < slots; ++k) {  // a key frame drawn in bands needs a third
    keys.colour_[k] = glo::make_exact_texture(GL_RGBA32F, width, height);
    // Multisampled, bilinear where all four pixels around a point saw its
    // surface (the resolve's one fetch); texel by texel elsewhere.
    glTextureParameteri(keys.colour_[k].get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(keys.colour_[k].get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    keys.depth_[k] = glo::make_exact_texture(depth_format, width, height);
    if (samples > 1) {
      keys.range_[k] = glo::make_exact_texture(GL_RG32F, width, height);
      keys.range_framebuffer_[k] = glo::make_framebuffer();
      const GLuint framebuffer = keys.range_framebuffer_[k].get();
      glNamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0, keys.range_[k].get(), 0);
      if (glCheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        return Error{"this GL driver cannot draw the up-conversion's key depth range (RG32F)"};
      }
    }
  }
  if (samples > 1) {
    auto range = glo::link_program(shaders::fullscreen_vert,
                                   std::string("#version 450 core\n") + std::string(shaders::key_depth_range_frag));
    if (!range) return Error{"the up-conversion's key depth range: " + range.error()};
    keys.range_program_ = std::move(range).value();
    glProgramUniform1i(keys.range_program_.get(), glGetUniformLocation(keys.range_program_.get(), "samples"), samples);
    keys.empty_vertex_array_ = glo::make_vertex_array();
  }
  return keys;
}

void KeyFrames::keep(int slot, GLuint colour, GLuint depth, GLuint sample_depth, up::KeyView view) {
  keep_rows(slot, colour, depth, sample_depth, std::move(view), 0, height_);
}

void KeyFrames::keep_rows(int slot, GLuint colour, GLuint depth, GLuint sample_depth, up::KeyView view, int first_row,
                          int rows) {
  assert(slot >= 0 && slot < slots_);
  assert(first_row >= 0 && rows >= 0 && first_row + rows <= height_);
  assert((samples_ > 1) == (sample_depth != 0));
  if (rows > 0) {
    copy(colour, colour_[slot].get(), width_, rows, first_row);
    copy(depth, depth_[slot].get(), width_, rows, first_row);
    if (samples_ > 1) {
      glBindFramebuffer(GL_FRAMEBUFFER, range_framebuffer_[slot].get());
      glViewport(0, 0, width_, height_);
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, first_row, width_, rows);
      glDisable(GL_DEPTH_TEST);
      glUseProgram(range_program_.get());
      glBindTextureUnit(0, sample_depth);
      glBindVertexArray(empty_vertex_array_.get());
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glDisable(GL_SCISSOR_TEST);
    }
  }
  view_[slot] = std::move(view);
}

void KeyFrames::restore(int slot, GLuint colour, GLuint depth) const {
  assert(slot >= 0 && slot < slots_);
  copy(colour_[slot].get(), colour, width_, height_);
  restore_depth(slot, depth);
}

void KeyFrames::restore_depth(int slot, GLuint depth) const {
  assert(slot >= 0 && slot < slots_);
  copy(depth_[slot].get(), depth, width_, height_);
}

const up::KeyView& KeyFrames::view(int slot) const {
  assert(slot >= 0 && slot < slots_);
  return view_[slot];
}

GLuint KeyFrames::colour(int slot) const {
  assert(slot >= 0 && slot < slots_);
  return colour_[slot].get();
}

GLuint KeyFrames::range(int slot) const {
  assert(slot >= 0 && slot < slots_ && samples_ > 1);
  return range_[slot].get();
}

}  // namespace optique::render
