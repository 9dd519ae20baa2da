#include "render/gl_objects.h"

#include <string>

namespace optique::render::glo {

namespace detail {
void delete_texture(GLuint name) { glDeleteTextures(1, &name); }
void delete_buffer(GLuint name) { glDeleteBuffers(1, &name); }
void delete_framebuffer(GLuint name) { glDeleteFramebuffers(1, &name); }
void delete_vertex_array(GLuint name) { glDeleteVertexArrays(1, &name); }
void delete_shader(GLuint name) { glDeleteShader(name); }
void delete_program(GLuint name) { glDeleteProgram(name); }
}  // namespace detail

Texture make_texture(GLenum target) {
  GLuint name = 0;
  glCreateTextures(target, 1, &name);
  return Texture(name);
}

Texture make_storage(GLenum format, int width, int height, int samples) {
  if (samples <= 1) {
    Texture texture = make_texture();
    glTextureStorage2D(texture.get(), 1, format, width, height);
    return texture;
  }
  Texture texture = make_texture(GL_TEXTURE_2D_MULTISAMPLE);
  glTextureStorage2DMultisample(texture.get(), samples, format, width, height, GL_TRUE);
  return texture;
}

Texture make_exact_texture(GLenum format, int width, int height) {
  Texture texture = make_storage(format, width, height);
  glTextureParameteri(texture.get(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(texture.get(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(texture.get(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return texture;
}

Buffer make_buffer() {
  GLuint name = 0;
  glCreateBuffers(1, &name);
  return Buffer(name);
}

Framebuffer make_framebuffer() {
  GLuint name = 0;
  glCreateFramebuffers(1, &name);
  return Framebuffer(name);
}

VertexArray make_vertex_array() {
  GLuint name = 0;
  glCreateVertexArrays(1, &name);
  return VertexArray(name);
}

namespace {

Result<Shader> compile(GLenum type, std::string_view source) {
  Shader shader(glCreateShader(type));
  const char* text = source.data();
  const auto length = static_cast<GLint>(source.size());
  glShaderSource(shader.get(), 1, &text, &length);
  glCompileShader(shader.get());
  GLint ok = GL_FALSE;
  glGetShaderiv(shader.get(), GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  char log[2048] = {};
  glGetShaderInfoLog(shader.get(), sizeof log, nullptr, log);
  return Error{std::string("shader does not compile: ") + log};
}

}  // namespace

Result<Program> link_program(std::string_view vertex_source, std::string_view fragment_source) {
  auto vertex = compile(GL_VERTEX_SHADER, vertex_source);
  if (!vertex) return Error{vertex.error()};
  auto fragment = compile(GL_FRAGMENT_SHADER, fragment_source);
  if (!fragment) return Error{fragment.error()};
  Program program(glCreateProgram());
  glAttachShader(program.get(), vertex.value().get());
  glAttachShader(program.get(), fragment.value().get());
  glLinkProgram(program.get());
  GLint ok = GL_FALSE;
  glGetProgramiv(program.get(), GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return program;
  char log[2048] = {};
  glGetProgramInfoLog(program.get(), sizeof log, nullptr, log);
  return Error{std::string("shader program does not link: ") + log};
}

image::FloatImage read_float(GLuint framebuffer, int width, int height, GLenum format, int channels) {
  image::FloatImage image(width, height, channels);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glReadBuffer(format == GL_DEPTH_COMPONENT ? GL_NONE : GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, format, GL_FLOAT, image.pixels.data());
  image::flip_rows(image);
  return image;
}

}  // namespace optique::render::glo
