#pragma once
// Frame-rate up-conversion's GL side: the key frames kept (colour and depth), the
// motion field of a frame between them (drawn by SceneRenderer with the scene's
// geometry), and the passes that build that frame from the key frames' pixels
// (glsl/between_resolve.frag.glsl) and mark what no key frame saw, so that only
// those pixels are shaded anew. On a multisampled projector the motion field,
// the frame and the shading anew are multisampled too (each sample of an edge
// pixel built from its own surface), then averaged into output(). Needs a
// current OpenGL 4.5 context; made only for projectors that up-convert, so the
// motion targets exist only there.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include <epoxy/gl.h>

#include "render/gl_objects.h"
#include "render/key_frames.h"
#include "up/between.h"
#include "util/result.h"

namespace optique::render {

class UpConverter {
 public:
  // For `width` × `height` pixels whose depth is `depth_format` (the scene
  // renderer's, GL_DEPTH_COMPONENT32F or 24), with `slots` key frames (2…
  // up::kKeySlots), `samples` per pixel (the scene renderer's).
  [[nodiscard]] static Result<std::unique_ptr<UpConverter>> create(int width, int height, GLenum depth_format,
                                                                   int slots = 2, int samples = 1);
  ~UpConverter();
  UpConverter(const UpConverter&) = delete;
  UpConverter& operator=(const UpConverter&) = delete;

  // The kept key frames the frames between are built from.
  [[nodiscard]] KeyFrames& keys() { return *keys_; }
  [[nodiscard]] const KeyFrames& keys() const { return *keys_; }

  // The motion field's target: where each pixel's surface was in each key frame
  // (attachment 0, and 1 `from_two` key frames) over the frame's own depth and
  // stencil; bound, cleared (no surface anywhere, stencil 0), depth test on.
  void begin_motion_field(bool from_two);
  // Then the frame from the key frames' pixels; with the motion method, the
  // pixels (samples) some key frame saw are marked in the stencil, and those
  // none saw are left for begin_shade_unseen() (frame.shade_unseen; otherwise
  // they show the first key frame's pixel) and counted.
  [[nodiscard]] up::BetweenReport resolve(const up::BetweenFrame& frame, const glm::vec3& background);
  // Binds the frame over the motion field's depth, drawing only where the
  // stencil leaves a pixel unseen and only the surface the field found there.
  void begin_shade_unseen();
  void end_shade_unseen();  // back to the GL state everything else expects
  // The frame done: multisampled, its samples averaged into output() and one
  // sample's depth into depth(); nothing to do otherwise.
  void finish();

  // PSNR_Y (the up-conversion paper's weighting of each channel's PSNR) of
  // output() against `image` (this size, RGBA32F, linear), both as displayed
  // (sRGB, 8-bit range); +infinity when equal, a channel equal alone 100 dB.
  [[nodiscard]] double psnr_y_against(GLuint image);

  // output()'s red, green and/or blue into `framebuffer` (this size), the other
  // channels left as they are.
  void write_channels(GLuint framebuffer, bool red, bool green, bool blue);

  [[nodiscard]] GLuint output() const { return output_.get(); }
  [[nodiscard]] GLuint output_framebuffer() const { return output_framebuffer_.get(); }  // with depth()
  [[nodiscard]] GLuint depth() const { return depth_stencil_.get(); }                    // the frame's own depth

 private:
  UpConverter() = default;
  int width_ = 0;
  int height_ = 0;
  int slots_ = 2;
  int samples_ = 1;
  std::optional<KeyFrames> keys_;  // made by create()
  // Where each pixel (sample) was in the first and the second key frame.
  std::array<glo::Texture, 2> motion_;
  glo::Texture depth_stencil_;  // output()'s; the motion field's too with one sample
  glo::Framebuffer motion_framebuffer_;
  glo::Texture output_;
  glo::Framebuffer output_framebuffer_;
  // Multisampled: the motion field's depth and stencil, and the frame before
  // its samples are averaged (drawn into by resolve() and the shading anew).
  glo::Texture multisample_depth_stencil_;
  glo::Texture multisample_frame_;
  glo::Framebuffer multisample_framebuffer_;
  [[nodiscard]] GLuint frame_framebuffer() const;  // where the frame is drawn
  // The resolve for each way: the average of two key frames (or one key frame
  // as it is, across a cut), motion from one key frame, from two.
  enum Resolve { average, average_one_key, one_key, two_keys, resolves };
  std::array<glo::Program, resolves> resolve_programs_;
  struct ResolveUniforms {
    GLint toward_second, background;
  };
  std::array<ResolveUniforms, resolves> uniforms_{};
  glo::Program error_program_;
  glo::Program channels_program_;
  glo::Texture error_sums_;  // one texel per kErrorBlock² pixels
  glo::Framebuffer error_framebuffer_;
  glo::VertexArray empty_vertex_array_;
  GLuint query_ = 0;
  glo::Buffer unseen_box_;      // glsl/between_resolve.frag.glsl: x0, y0, x1, y1
  std::array<GLint, 4> box_{};  // the last resolve's
};

}  // namespace optique::render
