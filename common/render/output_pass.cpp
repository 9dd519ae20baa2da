#include "render/output_pass.h"

#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "render/shaders.h"

namespace optique::render {
namespace {

// The output pass's choices for a stage, as the preprocessor constants it is
// built with (the enums' values are the shader's numbers).
std::string output_stage_defines(const OutputStage& stage) {
  return "#version 450 core\n#define WARP " + std::to_string(stage.projector_to_user ? 1 : 0) + "\n#define CURVE " +
         std::to_string(static_cast<int>(stage.projector.settings().curve)) + "\n#define SHARE " +
         std::to_string(static_cast<int>(stage.focus.role)) + "\n#define INSET " +
         std::to_string(stage.focus.inset ? 1 : 0) + "\n#define WEIGHTS " +
         std::to_string(stage.weights.empty() ? 0 : 1) + "\n";
}

// `framebuffer`'s RGBA as `type` (T's size), rows top first.
template <typename T>
image::Image<T> read_rgba(GLuint framebuffer, int width, int height, GLenum type) {
  image::Image<T> image(width, height, 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, sizeof(T));
  glReadPixels(0, 0, width, height, GL_RGBA, type, image.pixels.data());
  image::flip_rows(image);
  return image;
}

}  // namespace

Result<void> OutputPass::set(const OutputStage& stage) {
  const int width = stage.width > 0 ? stage.width : rendered_width_;
  const int height = stage.height > 0 ? stage.height : rendered_height_;
  if (!stage.weights.empty() &&
      (stage.weights.width != width || stage.weights.height != height || stage.weights.channels != 1)) {
    return Error{"blend weights are " + std::to_string(stage.weights.width) + "×" +
                 std::to_string(stage.weights.height) + "×" + std::to_string(stage.weights.channels) + ", the output " +
                 std::to_string(width) + "×" + std::to_string(height) + "×1"};
  }
  if (!stage.projector_to_user && (width != rendered_width_ || height != rendered_height_)) {
    return Error{"a single-pass output must have the rendered image's size"};
  }
  // The output pass for this stage, built before anything of the old one goes.
  const std::string source = output_stage_defines(stage) + std::string(shaders::output_frag);
  auto encode_program = glo::link_program(shaders::fullscreen_vert, source);
  if (!encode_program) return Error{encode_program.error()};
  if (!empty_vertex_array_) empty_vertex_array_ = glo::make_vertex_array();
  weights_.reset();
  width_ = width;
  height_ = height;
  // Its uniforms are set once here, not per frame.
  program_ = std::move(encode_program).value();
  const GLuint program = program_.get();
  focus_uniforms_ = {glGetUniformLocation(program, "coc"), glGetUniformLocation(program, "inset_disc")};
  // A single pass needs A⁻¹ too: a focus/defocus share undoes A's effect on depth.
  const glm::mat3 to_user(stage.projector_to_user.value_or(glm::inverse(stage.focus.user_to_projector)));
  const auto uniform = [program](const char* name) { return glGetUniformLocation(program, name); };
  glProgramUniformMatrix3fv(program, uniform("projector_to_user"), 1, GL_FALSE, glm::value_ptr(to_user));
  glProgramUniform2f(program, uniform("output_size"), static_cast<float>(width), static_cast<float>(height));
  glProgramUniform2f(program, uniform("rendered_size"), static_cast<float>(rendered_width_),
                     static_cast<float>(rendered_height_));

  projector_ = stage.projector;
  const optics::ProjectorModel& model = stage.projector;
  glProgramUniform1f(program, uniform("gamma"), static_cast<float>(model.settings().gamma));
  glProgramUniform1i(program, uniform("table_size"), static_cast<int>(model.settings().table.size()));
  glProgramUniform1f(program, uniform("levels"), static_cast<float>(model.levels()));
  glProgramUniform1f(program, uniform("black_level"), static_cast<float>(model.settings().black_level));
  glProgramUniform1f(program, uniform("brightness"), static_cast<float>(model.settings().brightness));
  {
    // A texture even when there is no table: every bound sampler needs one.
    std::vector<float> table(model.settings().table.begin(), model.settings().table.end());
    if (table.empty()) table = {0.0f, 1.0f};
    response_table_ = glo::make_texture();
    glTextureStorage2D(response_table_.get(), 1, GL_R32F, static_cast<GLsizei>(table.size()), 1);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(response_table_.get(), 0, 0, 0, static_cast<GLsizei>(table.size()), 1, GL_RED, GL_FLOAT,
                        table.data());
  }

  const FocusShare& focus = stage.focus;
  const glm::dmat3& a = focus.user_to_projector;
  glProgramUniform4f(program, uniform("depth_unwarp"), static_cast<float>(a[0][2]), static_cast<float>(a[1][2]),
                     static_cast<float>(a[2][2]), static_cast<float>(focus.depth_scale));
  const glm::mat3 fragment_to_screen(focus.fragment_to_screen);
  glProgramUniformMatrix3fv(program, uniform("fragment_to_screen"), 1, GL_FALSE, glm::value_ptr(fragment_to_screen));
  glProgramUniform1f(program, uniform("screen_metres_per_pixel"), static_cast<float>(focus.screen_metres_per_pixel));
  set_focus({});

  held_framebuffer_ = {};  // made again at this size when needed
  held_colour_ = {};
  encoded_colour_ = glo::make_texture();
  // The signal at the projector's depth: 8 bits, or 16 to hold up to 16.
  glTextureStorage2D(encoded_colour_.get(), 1, model.settings().bits <= 8 ? GL_RGBA8 : GL_RGBA16, width, height);
  encoded_framebuffer_ = glo::make_framebuffer();
  glNamedFramebufferTexture(encoded_framebuffer_.get(), GL_COLOR_ATTACHMENT0, encoded_colour_.get(), 0);
  if (!stage.weights.empty()) {
    image::FloatImage rows_up = stage.weights;  // GL's first row is the bottom one
    image::flip_rows(rows_up);
    weights_ = glo::make_texture();
    glTextureStorage2D(weights_.get(), 1, GL_R32F, width, height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(weights_.get(), 0, 0, 0, width, height, GL_RED, GL_FLOAT, rows_up.pixels.data());
  }
  const GLenum status = glCheckNamedFramebufferStatus(encoded_framebuffer_.get(), GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) return Error{"framebuffer incomplete (status " + std::to_string(status) + ")"};
  return {};
}

void OutputPass::set_focus(const FocusFrame& frame) {
  const GLuint program = program_.get();
  glProgramUniform4f(program, focus_uniforms_.coc, static_cast<float>(frame.coc.k), static_cast<float>(frame.coc.focal),
                     static_cast<float>(frame.coc.lo), static_cast<float>(frame.coc.hi));
  glProgramUniform3f(program, focus_uniforms_.inset_disc, static_cast<float>(frame.gaze.x),
                     static_cast<float>(frame.gaze.y), static_cast<float>(frame.inset_radius));
}

// The projector's response, last: linear light → what is sent to it.
void OutputPass::encode(GLuint colour, GLuint depth) {
  glBindFramebuffer(GL_FRAMEBUFFER, encoded_framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program_.get());
  glBindTextureUnit(0, colour);
  if (weights_) glBindTextureUnit(2, weights_.get());
  glBindTextureUnit(3, depth);
  glBindTextureUnit(4, response_table_.get());
  glBindVertexArray(empty_vertex_array_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glFinish();
}

void OutputPass::hold() {
  if (!held_framebuffer_) {
    held_colour_ = glo::make_texture();
    GLint format = 0;
    glGetTextureLevelParameteriv(encoded_colour_.get(), 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    glTextureStorage2D(held_colour_.get(), 1, static_cast<GLenum>(format), width_, height_);
    held_framebuffer_ = glo::make_framebuffer();
    glNamedFramebufferTexture(held_framebuffer_.get(), GL_COLOR_ATTACHMENT0, held_colour_.get(), 0);
  }
  glCopyImageSubData(encoded_colour_.get(), GL_TEXTURE_2D, 0, 0, 0, 0, held_colour_.get(), GL_TEXTURE_2D, 0, 0, 0, 0,
                     width_, height_, 1);
}

image::FloatImage OutputPass::read_linear() const {
  const image::WordImage signal = read_signal();
  image::FloatImage normalized(signal.width, signal.height, signal.channels);
  for (std::size_t i = 0; i < signal.pixels.size(); ++i) normalized.pixels[i] = signal.pixels[i] / 65535.0f;
  return optics::emitted_image(normalized, projector_);
}

image::ByteImage OutputPass::read_encoded() const {
  return read_rgba<std::uint8_t>(encoded_framebuffer_.get(), width_, height_, GL_UNSIGNED_BYTE);
}

image::WordImage OutputPass::read_signal() const {
  return read_rgba<std::uint16_t>(encoded_framebuffer_.get(), width_, height_, GL_UNSIGNED_SHORT);
}

}  // namespace optique::render
