#include "render/gl_context.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace optique::render {
namespace {

std::string egl_error(const char* what) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", static_cast<unsigned>(eglGetError()));
  return std::string(what) + " failed (EGL error " + code + ")";
}

class HeadlessContext final : public GlContext {
 public:
  HeadlessContext(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}
  ~HeadlessContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }
  void present(unsigned, int, int, image::ByteImage*) override {}
  [[nodiscard]] bool has_window() const override { return false; }

 private:
  EGLDisplay display_;
  EGLContext context_;
};

class WindowContext final : public GlContext {
 public:
  explicit WindowContext(GLFWwindow* window) : window_(window) {}
  ~WindowContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  void present(unsigned framebuffer, int width, int height, image::ByteImage* shown) override {
    int window_width = 0;
    int window_height = 0;
    glfwGetFramebufferSize(window_, &window_width, &window_height);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, width, height, 0, 0, window_width, window_height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    if (shown != nullptr) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
      glReadBuffer(GL_BACK);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      *shown = image::ByteImage(window_width, window_height, 4);
      glReadPixels(0, 0, window_width, window_height, GL_RGBA, GL_UNSIGNED_BYTE, shown->pixels.data());
      image::flip_rows(*shown);  // GL reads the bottom row first
    }
    glfwSwapBuffers(window_);
    glfwPollEvents();
  }
  [[nodiscard]] bool has_window() const override { return true; }

 private:
  GLFWwindow* window_;
};

}  // namespace

std::string GlContext::renderer_name() const {
  const auto* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return name != nullptr ? name : "unknown";
}

Result<std::unique_ptr<GlContext>> make_headless_context() {
  EGLDisplay display = EGL_NO_DISPLAY;
  if (epoxy_has_egl_extension(EGL_NO_DISPLAY, "EGL_MESA_platform_surfaceless")) {
    display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  }
  if (display == EGL_NO_DISPLAY) display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (display == EGL_NO_DISPLAY) return Error{"no EGL display: is an EGL driver (Mesa or the GPU vendor's) installed?"};
  EGLint major = 0;
  EGLint minor = 0;
  if (eglInitialize(display, &major, &minor) == EGL_FALSE) return Error{egl_error("eglInitialize")};
  if (eglBindAPI(EGL_OPENGL_API) == EGL_FALSE) {
    eglTerminate(display);
    return Error{egl_error("eglBindAPI(OpenGL)")};
  }
  const EGLint context_attributes[] = {
      EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  // Surfaceless: no config and no surface; everything is drawn into framebuffer objects.
  EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    const std::string error = egl_error("eglCreateContext(OpenGL 4.5 core)");
    eglTerminate(display);
    return Error{error};
  }
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) == EGL_FALSE) {
    const std::string error = egl_error("eglMakeCurrent");
    eglDestroyContext(display, context);
    eglTerminate(display);
    return Error{error};
  }
  return std::unique_ptr<GlContext>(new HeadlessContext(display, context));
}

Result<std::unique_ptr<GlContext>> make_window_context(const std::string& title, int width, int height, int monitor,
                                                       bool fullscreen) {
  if (glfwInit() == GLFW_FALSE) {
    const char* description = nullptr;
    glfwGetError(&description);
    return Error{std::string("cannot open a window (is there a display?): ") +
                 (description != nullptr ? description : "glfwInit failed")};
  }
  GLFWmonitor* target = nullptr;
  if (fullscreen) {
    int count = 0;
    GLFWmonitor** monitors = glfwGetMonitors(&count);
    if (monitor < 0 || monitor >= count) {
      glfwTerminate();
      return Error{"monitor " + std::to_string(monitor) + " does not exist (this display has " + std::to_string(count) +
                   ")"};
    }
    target = monitors[monitor];
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* window = glfwCreateWindow(width, height, title.c_str(), target, nullptr);
  if (window == nullptr) {
    const char* description = nullptr;
    glfwGetError(&description);
    glfwTerminate();
    return Error{std::string("cannot create an OpenGL 4.5 window: ") + (description != nullptr ? description : "?")};
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);  // vsync: a swap lands on the projector's refresh
  return std::unique_ptr<GlContext>(new WindowContext(window));
}

}  // namespace optique::render
