#pragma once
// OpenGL objects that delete themselves: a texture, buffer, framebuffer, vertex
// array, shader or program name owned by one value, moved and never copied, and
// given back to GL when the value goes (with its context current, as every GL
// call needs). And the one way to build a program from GLSL sources, with the
// driver's message when it does not compile or link, and the one way to read
// a framebuffer back as floats.

#include <epoxy/gl.h>

#include <string_view>
#include <utility>

#include "image/image.h"
#include "util/result.h"

namespace optique::render::glo {

template <void (*Delete)(GLuint)>
class Object {
 public:
  Object() = default;
  explicit Object(GLuint name) : name_(name) {}
  ~Object() { reset(); }
  Object(Object&& other) noexcept : name_(std::exchange(other.name_, 0)) {}
  Object& operator=(Object&& other) noexcept {
    if (this != &other) {
      reset();
      name_ = std::exchange(other.name_, 0);
    }
    return *this;
  }
  Object(const Object&) = delete;
  Object& operator=(const Object&) = delete;

  [[nodiscard]] GLuint get() const { return name_; }
  [[nodiscard]] explicit operator bool() const { return name_ != 0; }
  void reset() {
    if (name_ != 0) Delete(std::exchange(name_, 0));
  }

 private:
  GLuint name_ = 0;
};

namespace detail {
void delete_texture(GLuint name);
void delete_buffer(GLuint name);
void delete_framebuffer(GLuint name);
void delete_vertex_array(GLuint name);
void delete_shader(GLuint name);
void delete_program(GLuint name);
}  // namespace detail

using Texture = Object<detail::delete_texture>;
using Buffer = Object<detail::delete_buffer>;
using Framebuffer = Object<detail::delete_framebuffer>;
using VertexArray = Object<detail::delete_vertex_array>;
using Shader = Object<detail::delete_shader>;
using Program = Object<detail::delete_program>;

[[nodiscard]] Texture make_texture(GLenum target = GL_TEXTURE_2D);
// Storage of `format` for an attachment, multisampled (fixed sample
// locations, as every multisampled target here: they share framebuffers) when
// `samples` > 1.
[[nodiscard]] Texture make_storage(GLenum format, int width, int height, int samples = 1);
// A single-sample texture read texel by texel (nearest, clamped).
[[nodiscard]] Texture make_exact_texture(GLenum format, int width, int height);
[[nodiscard]] Buffer make_buffer();
[[nodiscard]] Framebuffer make_framebuffer();
[[nodiscard]] VertexArray make_vertex_array();

// Compiles and links; fails with the driver's log.
[[nodiscard]] Result<Program> link_program(std::string_view vertex_source, std::string_view fragment_source);

// `framebuffer`'s colour attachment 0 (or its depth, for GL_DEPTH_COMPONENT) as
// floats, rows top first.
[[nodiscard]] image::FloatImage read_float(GLuint framebuffer, int width, int height, GLenum format, int channels);

}  // namespace optique::render::glo
