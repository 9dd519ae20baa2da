#pragma once
// Internal to render: frame-rate up-conversion's kept key frames
// (render/up_converter.h builds the frames between from them). Each slot holds
// a drawn image (RGBA32F, its alpha the window depth as the scene's program
// writes it), its depth, how it was drawn (up::KeyView), and, multisampled,
// the nearest and farthest sample depth of each pixel.

#include <array>

#include <epoxy/gl.h>

#include "render/gl_objects.h"
#include "up/between.h"
#include "util/result.h"

namespace optique::render {

class KeyFrames {
 public:
  // `slots` key frames (2… up::kKeySlots) of `width` × `height` pixels, depth
  // in `depth_format`, drawn with `samples` per pixel.
  [[nodiscard]] static Result<KeyFrames> create(int width, int height, GLenum depth_format, int slots, int samples);

  // Copies a drawn image and its depth into slot `slot`; multisampled,
  // `sample_depth` is its depth per sample (before the resolve: which pixels
  // hold more than one surface).
  void keep(int slot, GLuint colour, GLuint depth, GLuint sample_depth, up::KeyView view);
  // Only `rows` rows from `first_row` (a band of a key frame drawn in bands).
  void keep_rows(int slot, GLuint colour, GLuint depth, GLuint sample_depth, up::KeyView view, int first_row, int rows);
  // And back: key `slot`'s colour and depth into these, or its depth alone.
  void restore(int slot, GLuint colour, GLuint depth) const;
  void restore_depth(int slot, GLuint depth) const;

  [[nodiscard]] const up::KeyView& view(int slot) const;
  [[nodiscard]] GLuint colour(int slot) const;
  [[nodiscard]] GLuint range(int slot) const;  // multisampled only (RG32F: nearest, farthest)

 private:
  KeyFrames() = default;
  int width_ = 0;
  int height_ = 0;
  int slots_ = 2;
  int samples_ = 1;
  std::array<glo::Texture, up::kKeySlots> colour_;
  std::array<glo::Texture, up::kKeySlots> depth_;
  std::array<up::KeyView, up::kKeySlots> view_;
  std::array<glo::Texture, up::kKeySlots> range_;
  std::array<glo::Framebuffer, up::kKeySlots> range_framebuffer_;
  glo::Program range_program_;
  glo::VertexArray empty_vertex_array_;
};

}  // namespace optique::render
