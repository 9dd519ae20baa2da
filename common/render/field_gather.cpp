#include "render/field_gather.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <vector>

#include "render/shaders.h"

namespace optique::render {
namespace {

constexpr std::string_view kVersion = "#version 450 core\n";

Result<glo::Program> fullscreen_program(std::string_view fragment) {
  return glo::link_program(shaders::fullscreen_vert, std::string(kVersion) + std::string(fragment));
}

// Two triangles per tile, in NDC: 12 floats.
constexpr std::size_t kFloatsPerTile = 12;

// A single-sample float texture and a framebuffer that draws into it.
void make_target(GLenum format, int width, int height, glo::Texture& texture, glo::Framebuffer& framebuffer) {
  texture = glo::make_texture();
  glTextureStorage2D(texture.get(), 1, format, width, height);
  glTextureParameteri(texture.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(texture.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  framebuffer = glo::make_framebuffer();
  glNamedFramebufferTexture(framebuffer.get(), GL_COLOR_ATTACHMENT0, texture.get(), 0);
}

}  // namespace

Result<std::unique_ptr<FieldGather>> FieldGather::create(int width, int height, int samples) {
  assert(width > 0 && height > 0 && samples >= 1);
  std::unique_ptr<FieldGather> g(new FieldGather());
  g->width_ = width;
  g->height_ = height;
  g->samples_ = samples;
  g->tiles_x_ = (width + kGatherRadius - 1) / kGatherRadius;
  g->tiles_y_ = (height + kGatherRadius - 1) / kGatherRadius;
  struct Built {
    glo::Program* program;
    std::string_view source;
    const char* name;
  };
  for (const Built& b : {Built{&g->resolve_program_, shaders::motion_resolve_frag, "motion resolve"},
                         Built{&g->tile_max_program_, shaders::tile_max_frag, "tile max"},
                         Built{&g->neighbour_max_program_, shaders::neighbour_max_frag, "neighbour max"}}) {
    auto program = fullscreen_program(b.source);
    if (!program) return Error{std::string("the ") + b.name + " pass: " + program.error()};
    *b.program = std::move(program).value();
  }
  auto gather_program = glo::link_program(std::string(kVersion) + std::string(shaders::tiles_vert),
                                          std::string(kVersion) + std::string(shaders::field_gather_frag));
  if (!gather_program) return Error{"the field gather pass: " + gather_program.error()};
  g->gather_program_ = std::move(gather_program).value();
  // Velocity in pixels and depth in metres as half floats: 0.01 px at 20 px per
  // frame, about 4 mm at 5 m (surfaces closer than that in depth are one layer).
  make_target(GL_RGBA16F, width, height, g->motion_, g->motion_framebuffer_);
  if (samples > 1) {
    g->motion_samples_ = glo::make_storage(GL_RGBA16F, width, height, samples);
  }
  make_target(GL_RGBA32F, width, height, g->gathered_, g->gathered_framebuffer_);
  // Read by the output pass like the linear image: bilinear for a two-pass warp.
  glTextureParameteri(g->gathered_.get(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(g->gathered_.get(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  make_target(GL_RG32F, g->tiles_x_, g->tiles_y_, g->tile_max_, g->tile_max_framebuffer_);
  make_target(GL_RG32F, g->tiles_x_, g->tiles_y_, g->neighbour_max_, g->neighbour_max_framebuffer_);
  g->tile_quads_ = glo::make_buffer();
  glNamedBufferStorage(
      g->tile_quads_.get(),
      static_cast<GLsizeiptr>(static_cast<std::size_t>(g->tiles_x_) * static_cast<std::size_t>(g->tiles_y_) *
                              kFloatsPerTile * sizeof(GLfloat)),
      nullptr, GL_DYNAMIC_STORAGE_BIT);
  g->tile_vertex_array_ = glo::make_vertex_array();
  const GLuint va = g->tile_vertex_array_.get();
  glVertexArrayVertexBuffer(va, 0, g->tile_quads_.get(), 0, 2 * sizeof(GLfloat));
  glEnableVertexArrayAttrib(va, 0);
  glVertexArrayAttribFormat(va, 0, 2, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(va, 0, 0);
  for (GLuint fb : {g->motion_framebuffer_.get(), g->tile_max_framebuffer_.get(), g->neighbour_max_framebuffer_.get(),
                    g->gathered_framebuffer_.get()}) {
    if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"this GL driver cannot draw the gather's targets (RGBA16F, RG32F, RGBA32F)"};
    }
  }
  g->empty_vertex_array_ = glo::make_vertex_array();
  glProgramUniform1i(g->resolve_program_.get(), glGetUniformLocation(g->resolve_program_.get(), "samples"), samples);
  glProgramUniform1i(g->tile_max_program_.get(), glGetUniformLocation(g->tile_max_program_.get(), "tile"),
                     kGatherRadius);
  const GLuint gather = g->gather_program_.get();
  glProgramUniform1i(gather, glGetUniformLocation(gather, "tile"), kGatherRadius);
  glProgramUniform1f(gather, glGetUniformLocation(gather, "radius"), static_cast<float>(kGatherRadius));
  return g;
}

GLuint FieldGather::motion_target() const { return samples_ > 1 ? motion_samples_.get() : motion_.get(); }

void FieldGather::clear_motion(GLuint framebuffer) {
  const GLfloat still_and_far[4] = {0.0f, 0.0f, 3.0e38f, 0.0f};
  glClearNamedFramebufferfv(framebuffer, GL_COLOR, 1, still_and_far);
}

void FieldGather::measure() {
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(empty_vertex_array_.get());
  const auto pass = [&](GLuint program, GLuint framebuffer, int width, int height) {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glViewport(0, 0, width, height);
    glUseProgram(program);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  };
  if (samples_ > 1) {
    glBindTextureUnit(0, motion_samples_.get());
    pass(resolve_program_.get(), motion_framebuffer_.get(), width_, height_);
  }
  glBindTextureUnit(0, motion_.get());
  pass(tile_max_program_.get(), tile_max_framebuffer_.get(), tiles_x_, tiles_y_);
  glBindTextureUnit(0, tile_max_.get());
  pass(neighbour_max_program_.get(), neighbour_max_framebuffer_.get(), tiles_x_, tiles_y_);

  // Each tile's fastest within reach (a few thousand values, the neighbour max
  // the shader reads): which tiles to gather, and whether the radius cut a
  // field's motion short.
  std::vector<GLfloat> tiles(static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>(tiles_y_) * 2);
  glGetTextureImage(neighbour_max_.get(), 0, GL_RG, GL_FLOAT, static_cast<GLsizei>(tiles.size() * sizeof(GLfloat)),
                    tiles.data());
  near_.assign(tiles.size() / 2, 0.0);
  fastest_ = 0.0;
  for (std::size_t i = 0; i < near_.size(); ++i) {
    near_[i] = std::hypot(double{tiles[2 * i]}, double{tiles[2 * i + 1]});
    fastest_ = std::max(fastest_, near_[i]);
  }
}

void FieldGather::keep(GLuint image) {
  glCopyImageSubData(image, GL_TEXTURE_2D, 0, 0, 0, 0, gathered_.get(), GL_TEXTURE_2D, 0, 0, 0, 0, width_, height_, 1);
}

GatherReport FieldGather::gather(GLuint colour, std::span<const GatherField> fields, const GatherSettings& settings) {
  assert(fields.size() <= static_cast<std::size_t>(kMaxGatherFields));
  assert(settings.samples >= 2);
  const bool blur_only = fields.empty();
  assert(!blur_only || settings.velocity_threshold > 0.0);
  assert(near_.size() == static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>(tiles_y_));  // measure() first
  GatherReport report;
  report.fastest = fastest_;
  double farthest_shift = 0.0;
  for (const GatherField& f : fields) farthest_shift = std::max(farthest_shift, std::abs(f.shift));
  const double threshold = settings.velocity_threshold;
  const bool blurs = threshold > 0.0 && report.fastest > kBlurBandFrom * threshold;
  const double reach = std::max(
      {farthest_shift, blurs ? std::abs(settings.frame_start) : 0.0, blurs ? std::abs(settings.frame_end) : 0.0});
  report.clamped = report.fastest * reach > kGatherRadius;

  // The render as it is; then, over it, the tiles where a field moves something
  // (the shader's own test: a neighbour max that moves a surface 1e-3 px), or
  // where the blur begins.
  if (!blur_only) keep(colour);
  const double slowest = blur_only ? kBlurBandFrom * threshold : 0.0;
  std::vector<GLfloat> quads;
  const auto ndc = [](int pixel, int size) { return static_cast<GLfloat>(2.0 * pixel / size - 1.0); };
  for (int ty = 0; ty < tiles_y_; ++ty) {
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const double near =
          near_[static_cast<std::size_t>(ty) * static_cast<std::size_t>(tiles_x_) + static_cast<std::size_t>(tx)];
      if (near * reach < 1e-3 || near <= slowest) continue;
      const GLfloat x0 = ndc(tx * kGatherRadius, width_);
      const GLfloat x1 = ndc(std::min((tx + 1) * kGatherRadius, width_), width_);
      const GLfloat y0 = ndc(ty * kGatherRadius, height_);
      const GLfloat y1 = ndc(std::min((ty + 1) * kGatherRadius, height_), height_);
      quads.insert(quads.end(), {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1});
    }
  }
  report.gathered_tiles = static_cast<int>(quads.size() / kFloatsPerTile);
  if (quads.empty()) return report;

  const GLuint gather = gather_program_.get();
  const auto uniform = [gather](const char* name) { return glGetUniformLocation(gather, name); };
  std::vector<GLfloat> channels;
  std::vector<GLfloat> shifts;
  for (const GatherField& f : fields) {
    channels.insert(channels.end(), {f.red ? 1.0f : 0.0f, f.green ? 1.0f : 0.0f, f.blue ? 1.0f : 0.0f});
    shifts.push_back(static_cast<GLfloat>(f.shift));
  }
  const auto count = static_cast<GLsizei>(fields.size());
  glProgramUniform1i(gather, uniform("field_count"), count);
  if (count > 0) {
    glProgramUniform3fv(gather, uniform("field_channels"), count, channels.data());
    glProgramUniform1fv(gather, uniform("field_shift"), count, shifts.data());
  }
  glProgramUniform1i(gather, uniform("samples"), settings.samples);
  glProgramUniform2f(gather, uniform("blur_band"), static_cast<float>(kBlurBandFrom * threshold),
                     static_cast<float>(kBlurBandTo * threshold));
  glProgramUniform2f(gather, uniform("frame_shift"), static_cast<float>(settings.frame_start),
                     static_cast<float>(settings.frame_end));
  glBindTextureUnit(0, colour);
  glBindTextureUnit(1, motion_.get());
  glBindTextureUnit(2, neighbour_max_.get());
  glNamedBufferSubData(tile_quads_.get(), 0, static_cast<GLsizeiptr>(quads.size() * sizeof(GLfloat)), quads.data());
  glBindFramebuffer(GL_FRAMEBUFFER, gathered_framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  if (blur_only) {  // the shader gives the blur and its weight: over the fields, alpha kept
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  }
  glUseProgram(gather);
  glBindVertexArray(tile_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(quads.size() / 2));
  glDisable(GL_BLEND);
  // With one sample per pixel the motion texture is also the scene's second
  // attachment: left bound, the next scene pass would sample what it draws into.
  glBindTextureUnit(1, 0);
  return report;
}

}  // namespace optique::render
