#pragma once
// An OpenGL 4.5 core context, headless (EGL surfaceless: no X server, Mesa's
// llvmpipe here or the vendor driver on a GPU machine) or in a window on a
// projector (GLFW, fullscreen on a monitor, vsync). Rendering code does not know
// which: it draws into its own framebuffer, and present() shows that on the
// window, if there is one.

#include <memory>
#include <string>

#include "image/image.h"
#include "util/result.h"

namespace optique::render {

class GlContext {
 public:
  virtual ~GlContext() = default;
  // Shows `framebuffer` (width × height, already drawn): a blit to the window and a
  // buffer swap; headless, nothing to show. With `shown`, a window also reads back
  // what it is about to show (its back buffer after the blit, before the swap;
  // RGBA8, top row first, the window's size), so tests can check the window itself.
  virtual void present(unsigned framebuffer, int width, int height, image::ByteImage* shown = nullptr) = 0;
  [[nodiscard]] virtual bool has_window() const = 0;
  // "llvmpipe (LLVM 15.0.6, 256 bits)", for logs and benchmark tables.
  [[nodiscard]] std::string renderer_name() const;
};

// The context is current on the calling thread when these return.
[[nodiscard]] Result<std::unique_ptr<GlContext>> make_headless_context();
[[nodiscard]] Result<std::unique_ptr<GlContext>> make_window_context(const std::string& title, int width, int height,
                                                                     int monitor, bool fullscreen);

}  // namespace optique::render
