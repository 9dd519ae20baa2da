#pragma once
// The mean of each factor × factor block of a framebuffer's colour, taken by GL
// and read back at the reduced size. A supersampled image then leaves the GPU
// factor² times smaller: perceive's ideal is 32 moments of 4224 × 2376 RGBA32F
// (160 MB each), which read back whole, flipped and averaged on one core took
// about half of perceive's time.

#include "image/image.h"
#include "render/gl_objects.h"
#include "util/result.h"

namespace optique::render {

class BoxReduce {
 public:
  // Needs a current GL context. `width` × `height`: the reduced image;
  // `factor` ≥ 1: the source is factor times as wide and as high.
  [[nodiscard]] static Result<BoxReduce> make(int width, int height, int factor);

  // The reduced colour of `framebuffer`'s first attachment, which must be a
  // single-sampled texture of exactly the source's size: linear RGBA, rows top
  // first (as SceneRenderer::read_rendered), alpha 1.
  [[nodiscard]] Result<image::FloatImage> read(unsigned framebuffer) const;

  [[nodiscard]] int factor() const { return factor_; }

 private:
  BoxReduce() = default;

  int width_ = 0;
  int height_ = 0;
  int factor_ = 1;
  glo::Program program_;
  GLint source_location_ = -1;
  GLint factor_location_ = -1;
  glo::Texture reduced_;
  glo::Framebuffer framebuffer_;
  glo::VertexArray empty_vertex_array_;
};

}  // namespace optique::render
