#pragma once
// The gather method of colour fields: the scene drawn once with its screen-space
// velocity and linear depth, and each field built from that one image along the
// motion (glsl/field_gather.frag.glsl), instead of one render per field.
// Needs a current OpenGL 4.5 context; made only for projectors that use it, so
// the velocity target and tiles exist only there.

#include <memory>
#include <span>
#include <vector>

#include <epoxy/gl.h>

#include "render/fields.h"
#include "render/gl_objects.h"
#include "util/result.h"

namespace optique::render {

class FieldGather {
 public:
  // A gather for `width` × `height` pixels drawn with `samples` per pixel.
  [[nodiscard]] static Result<std::unique_ptr<FieldGather>> create(int width, int height, int samples);

  // Where the scene's velocity and depth are drawn (attachment 1 beside its
  // colour): multisampled when the scene is.
  [[nodiscard]] GLuint motion_target() const;
  // The value a pixel the scene does not cover holds: still, infinitely far.
  static void clear_motion(GLuint framebuffer);

  // After the scene is drawn: its velocity resolved (multisampled), the tile
  // max and neighbour max, and how fast each tile's neighbourhood moves.
  void measure();
  // Then, from its colour resolved into `colour` (one sample per pixel, this
  // size): each field's channels into output(). At most kMaxGatherFields fields,
  // each channel in one of them. Only the tiles where something moves are
  // gathered; the others are the render as it is. Again for another image's
  // fields from the same render (a stereo projector used as mono).
  // Without fields, only the motion blur above the threshold (which must be
  // set), laid over the image keep() put in output(): fields drawn per field.
  [[nodiscard]] GatherReport gather(GLuint colour, std::span<const GatherField> fields, const GatherSettings& settings);
  void keep(GLuint image);  // `image` (this size, RGBA32F) into output()
  [[nodiscard]] GLuint output() const { return gathered_.get(); }

 private:
  FieldGather() = default;
  int width_ = 0;
  int height_ = 0;
  int samples_ = 1;
  int tiles_x_ = 0;
  int tiles_y_ = 0;
  std::vector<double> near_;  // per tile: its neighbour max's length (measure())
  double fastest_ = 0.0;
  glo::Texture motion_samples_;  // multisampled only
  glo::Texture motion_;          // one per pixel
  glo::Framebuffer motion_framebuffer_;
  glo::Texture tile_max_;
  glo::Framebuffer tile_max_framebuffer_;
  glo::Texture neighbour_max_;
  glo::Framebuffer neighbour_max_framebuffer_;
  glo::Program resolve_program_;
  glo::Program tile_max_program_;
  glo::Program neighbour_max_program_;
  glo::Program gather_program_;
  glo::VertexArray empty_vertex_array_;
  glo::Texture gathered_;
  glo::Framebuffer gathered_framebuffer_;
  glo::Buffer tile_quads_;  // the moving tiles' triangles, NDC, rewritten per frame
  glo::VertexArray tile_vertex_array_;
};

}  // namespace optique::render
