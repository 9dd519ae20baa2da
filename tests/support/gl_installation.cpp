#include "gl_installation.h"
#include "scene_load/installation_scene.h"

#include "image/texture_decode.h"
#include "scene_load/load_scene.h"

namespace optique::testing {

Result<GlInstallation> open_gl_installation(const std::string& config_path) {
  GlInstallation out;
  auto context = render::make_headless_context();
  if (!context) return Error{context.error()};
  out.context = std::move(context).value();
  auto loaded = config::load_installation(config_path);
  if (!loaded) return Error{loaded.error()};
  out.config = std::move(loaded).value();
  auto scene = config::load_scene(out.config.installation, image::decode_texture);
  if (!scene) return Error{scene.error()};
  out.scene = std::move(scene).value().definition;
  return out;
}

}  // namespace optique::testing
