#include "render/up_converter.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "render/shaders.h"

namespace optique::render {
namespace {

constexpr std::string_view kVersion = "#version 450 core\n";
constexpr int kErrorBlock = 16;  // pixels per side summed by one texel of the check
constexpr GLenum kBothKeys[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};  // the motion field's targets

}  // namespace

UpConverter::~UpConverter() {
  if (query_ != 0) glDeleteQueries(1, &query_);
}

Result<std::unique_ptr<UpConverter>> UpConverter::create(int width, int height, GLenum depth_format, int slots,
                                                         int samples) {
  assert(width > 0 && height > 0);
  assert(slots >= 2 && slots <= up::kKeySlots);
  assert(samples >= 1 && samples <= 16);  // the resolve's sample mask: (1 << SAMPLES) - 1
  std::unique_ptr<UpConverter> u(new UpConverter());
  u->width_ = width;
  u->height_ = height;
  u->slots_ = slots;
  u->samples_ = samples;
  for (int r = 0; r < resolves; ++r) {
    const bool averages = r == average || r == average_one_key;
    const bool one = r == one_key || r == average_one_key;
    const std::string head = std::string(kVersion) + "#define AVERAGE " + (averages ? "1" : "0") + "\n#define KEYS " +
                             (one ? "1" : "2") + "\n#define SAMPLES " + std::to_string(samples) + "\n";
    auto resolve = glo::link_program(shaders::fullscreen_vert, head + std::string(shaders::between_resolve_frag));
    if (!resolve) return Error{"the up-conversion's resolve pass: " + resolve.error()};
    u->resolve_programs_[r] = std::move(resolve).value();
    const GLuint p = u->resolve_programs_[r].get();
    u->uniforms_[r] = {glGetUniformLocation(p, "toward_second"), glGetUniformLocation(p, "background")};
  }
  auto error =
      glo::link_program(shaders::fullscreen_vert, std::string(kVersion) + std::string(shaders::between_error_frag));
  if (!error) return Error{"the up-conversion's check: " + error.error()};
  u->error_program_ = std::move(error).value();
  auto channels =
      glo::link_program(shaders::fullscreen_vert, std::string(kVersion) + std::string(shaders::between_channels_frag));
  if (!channels) return Error{"the up-conversion's colour fields: " + channels.error()};
  u->channels_program_ = std::move(channels).value();
  glProgramUniform1i(u->error_program_.get(), glGetUniformLocation(u->error_program_.get(), "block"), kErrorBlock);
  u->error_sums_ = glo::make_exact_texture(GL_RGBA32F, (width + kErrorBlock - 1) / kErrorBlock,
                                           (height + kErrorBlock - 1) / kErrorBlock);
  u->error_framebuffer_ = glo::make_framebuffer();
  glNamedFramebufferTexture(u->error_framebuffer_.get(), GL_COLOR_ATTACHMENT0, u->error_sums_.get(), 0);

  for (std::size_t k = 0; k < u->motion_.size(); ++k) {
    // Key-frame pixels in pixels, window depth at float precision: a depth
    // tolerance of a few 1e-6 must be representable. Read texel by texel.
    u->motion_[k] = samples > 1 ? glo::make_storage(GL_RGBA32F, width, height, samples)
                                : glo::make_exact_texture(GL_RGBA32F, width, height);
  }
  auto keys = KeyFrames::create(width, height, depth_format, slots, samples);
  if (!keys) return Error{keys.error()};
  u->keys_.emplace(std::move(keys).value());
  const GLenum depth_stencil = depth_format == GL_DEPTH_COMPONENT24 ? GL_DEPTH24_STENCIL8 : GL_DEPTH32F_STENCIL8;
  u->depth_stencil_ = glo::make_exact_texture(depth_stencil, width, height);
  u->output_ = glo::make_exact_texture(GL_RGBA32F, width, height);
  // Read by the output pass like the linear image: bilinear for a two-pass warp.
  glTextureParameteri(u->output_.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(u->output_.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);

  u->motion_framebuffer_ = glo::make_framebuffer();
  const GLuint motion = u->motion_framebuffer_.get();
  glNamedFramebufferTexture(motion, GL_COLOR_ATTACHMENT0, u->motion_[0].get(), 0);
  glNamedFramebufferTexture(motion, GL_COLOR_ATTACHMENT1, u->motion_[1].get(), 0);
  u->output_framebuffer_ = glo::make_framebuffer();
  glNamedFramebufferTexture(u->output_framebuffer_.get(), GL_COLOR_ATTACHMENT0, u->output_.get(), 0);
  glNamedFramebufferTexture(u->output_framebuffer_.get(), GL_DEPTH_STENCIL_ATTACHMENT, u->depth_stencil_.get(), 0);
  if (glCheckNamedFramebufferStatus(u->error_framebuffer_.get(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Error{"this GL driver cannot draw the up-conversion's check (RGBA32F)"};
  }
  // The motion field and the frame share their depth and stencil: the resolve
  // marks, the shading anew tests. Multisampled, they share multisampled ones,
  // and output() has its own single-sample depth (finish()).
  GLuint frame_depth_stencil = u->depth_stencil_.get();
  if (samples > 1) {
    u->multisample_depth_stencil_ = glo::make_storage(depth_stencil, width, height, samples);
    u->multisample_frame_ = glo::make_storage(GL_RGBA32F, width, height, samples);
    u->multisample_framebuffer_ = glo::make_framebuffer();
    glNamedFramebufferTexture(u->multisample_framebuffer_.get(), GL_COLOR_ATTACHMENT0, u->multisample_frame_.get(), 0);
    glNamedFramebufferTexture(u->multisample_framebuffer_.get(), GL_DEPTH_STENCIL_ATTACHMENT,
                              u->multisample_depth_stencil_.get(), 0);
    frame_depth_stencil = u->multisample_depth_stencil_.get();
  }
  glNamedFramebufferTexture(motion, GL_DEPTH_STENCIL_ATTACHMENT, frame_depth_stencil, 0);
  for (GLuint fb : {motion, u->output_framebuffer_.get(), u->frame_framebuffer()}) {
    if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"this GL driver cannot draw the up-conversion's targets (RGBA32F with depth and stencil, " +
                   std::to_string(samples) + " sample(s) per pixel)"};
    }
  }
  u->empty_vertex_array_ = glo::make_vertex_array();
  glCreateQueries(GL_SAMPLES_PASSED, 1, &u->query_);
  u->unseen_box_ = glo::make_buffer();
  glNamedBufferStorage(u->unseen_box_.get(), sizeof(GLint) * 4, nullptr, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
  return u;
}

void UpConverter::begin_motion_field(bool from_two) {
  const GLuint fb = motion_framebuffer_.get();
  glNamedFramebufferDrawBuffers(fb, from_two ? 2 : 1, kBothKeys);
  glBindFramebuffer(GL_FRAMEBUFFER, fb);
  glViewport(0, 0, width_, height_);
  const GLfloat no_surface[4] = {0.0f, 0.0f, 0.0f, -2.0f};
  glClearNamedFramebufferfv(fb, GL_COLOR, 0, no_surface);
  if (from_two) glClearNamedFramebufferfv(fb, GL_COLOR, 1, no_surface);
  glClearNamedFramebufferfi(fb, GL_DEPTH_STENCIL, 0, 1.0f, 0);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
}

GLuint UpConverter::frame_framebuffer() const {
  return samples_ > 1 ? multisample_framebuffer_.get() : output_framebuffer_.get();
}

up::BetweenReport UpConverter::resolve(const up::BetweenFrame& frame, const glm::vec3& background) {
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(empty_vertex_array_.get());
  glBindFramebuffer(GL_FRAMEBUFFER, frame_framebuffer());
  glViewport(0, 0, width_, height_);
  const bool averages = frame.method == up::BetweenMethod::average;
  const Resolve r = averages ? (frame.two_keys ? average : average_one_key) : frame.two_keys ? two_keys : one_key;
  if (!averages && !frame.shade_unseen) {
    // What no key frame saw keeps the first key frame's pixel (the resolve
    // leaves it): drawn into every sample.
    glUseProgram(channels_program_.get());
    glBindTextureUnit(0, keys_->colour(frame.first));
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glUseProgram(resolve_programs_[r].get());
  glUniform1f(uniforms_[r].toward_second, static_cast<float>(frame.toward_second));
  glUniform3f(uniforms_[r].background, background.r, background.g, background.b);
  assert(frame.first >= 0 && frame.first < slots_);
  assert(!frame.two_keys || (frame.second >= 0 && frame.second < slots_ && frame.second != frame.first));
  for (int k = 0; k < 2; ++k) {  // the first key frame as key 0
    const int slot = k == 0 || !frame.two_keys ? frame.first : frame.second;
    glBindTextureUnit(static_cast<GLuint>(k), keys_->colour(slot));
    // Multisampled, the depth range (glsl/key_depth_range.frag.glsl); with one
    // sample the key colour's alpha is its depth.
    if (samples_ > 1) glBindTextureUnit(static_cast<GLuint>(2 + k), keys_->range(slot));
    glBindTextureUnit(static_cast<GLuint>(4 + k), motion_[k].get());  // the motion field's, in that order
  }
  if (averages) {
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return {};
  }
  // Every pixel (sample) the resolve wrote is marked in the stencil and
  // counted; it discards those no key frame saw (one pass: a second that read
  // the output back to mark them cost llvmpipe 2 ms at 1280×720).
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, 1, 0xFF);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  const GLint empty[4] = {width_, height_, -1, -1};
  glNamedBufferSubData(unseen_box_.get(), 0, sizeof(empty), empty);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, unseen_box_.get());
  glBeginQuery(GL_SAMPLES_PASSED, query_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEndQuery(GL_SAMPLES_PASSED);
  glDisable(GL_STENCIL_TEST);
  GLint64 resolved = 0;
  glGetQueryObjecti64v(query_, GL_QUERY_RESULT, &resolved);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glGetNamedBufferSubData(unseen_box_.get(), 0, sizeof(GLint) * 4, box_.data());
  const GLint64 all = static_cast<GLint64>(width_) * height_ * samples_;
  const GLint64 unseen = std::max<GLint64>(0, all - resolved);  // samples
  up::BetweenReport report;
  report.unseen_pixels = (unseen + samples_ - 1) / samples_;  // in pixels' worth, none only if none
  report.unseen_share = static_cast<double>(unseen) / static_cast<double>(all);
  return report;
}

double UpConverter::psnr_y_against(GLuint image) {
  const int columns = (width_ + kErrorBlock - 1) / kErrorBlock;
  const int rows = (height_ + kErrorBlock - 1) / kErrorBlock;
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, error_framebuffer_.get());
  glViewport(0, 0, columns, rows);
  glUseProgram(error_program_.get());
  glBindTextureUnit(0, output_.get());
  glBindTextureUnit(1, image);
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  std::vector<float> sums(static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows) * 4);
  glGetTextureImage(error_sums_.get(), 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(sums.size() * sizeof(float)),
                    sums.data());
  double squared[3] = {0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < sums.size(); i += 4) {
    for (int c = 0; c < 3; ++c) squared[c] += sums[i + static_cast<std::size_t>(c)];
  }
  const double pixels = static_cast<double>(width_) * static_cast<double>(height_);
  const double weights[3] = {0.299, 0.587, 0.114};
  // A channel identical everywhere (a share without blue) counts as 100 dB,
  // as a 4×4 block's does (image/compare.h): the others still weigh.
  constexpr double kIdentical = 100.0;
  double psnr = 0.0;
  bool all_identical = true;
  for (int c = 0; c < 3; ++c) {
    all_identical = all_identical && squared[c] <= 0.0;
    psnr +=
        weights[c] * (squared[c] <= 0.0 ? kIdentical : std::min(kIdentical, 10.0 * std::log10(pixels / squared[c])));
  }
  return all_identical ? std::numeric_limits<double>::infinity() : psnr;
}

void UpConverter::write_channels(GLuint framebuffer, bool red, bool green, bool blue) {
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glColorMask(red, green, blue, GL_FALSE);
  glUseProgram(channels_program_.get());
  glBindTextureUnit(0, output_.get());
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void UpConverter::begin_shade_unseen() {
  glBindFramebuffer(GL_FRAMEBUFFER, frame_framebuffer());
  glViewport(0, 0, width_, height_);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_EQUAL, 0, 0xFF);  // what the resolve left
  glEnable(GL_SCISSOR_TEST);         // within the box around it
  glScissor(box_[0], box_[1], std::max(0, box_[2] - box_[0] + 1), std::max(0, box_[3] - box_[1] + 1));
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);  // the same surface the motion field found (invariant positions)
  glDepthMask(GL_FALSE);
  glDisable(GL_CULL_FACE);
}

void UpConverter::end_shade_unseen() {
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_SCISSOR_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

void UpConverter::finish() {
  if (samples_ == 1) return;
  // The samples averaged (linear light), as the scene renderer resolves its
  // own; depth from one sample, for the passes that read it.
  glBlitNamedFramebuffer(multisample_framebuffer_.get(), output_framebuffer_.get(), 0, 0, width_, height_, 0, 0, width_,
                         height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBlitNamedFramebuffer(multisample_framebuffer_.get(), output_framebuffer_.get(), 0, 0, width_, height_, 0, 0, width_,
                         height_, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

}  // namespace optique::render
