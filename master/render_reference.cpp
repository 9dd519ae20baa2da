#include "render_reference.h"

#include <cmath>
#include <filesystem>

#include "image/frame_files.h"
#include "render/gl_context.h"
#include "render/projection.h"
#include "render/scene_renderer.h"
#include "scene_authority.h"

namespace optique::master {

Result<void> render_reference(const config::LoadedConfig& config, const scene::LoadedScene& scene, std::uint64_t frame,
                              const std::string& out_dir, spdlog::logger& log) {
  const auto& installation = config.installation;
  const SceneAuthority authority(scene.definition.objects, installation.viewer(), installation.master().frame_rate());
  const scene::SceneState state = authority.state_at_frame(frame);

  auto context = render::make_headless_context();
  if (!context) return Error{"cannot render: " + context.error()};
  const auto& viewer = installation.viewer();
  for (const auto& screen : installation.screens()) {
    const int width = static_cast<int>(std::lround(screen.width() * screen.pixels_per_metre()));
    const int height = static_cast<int>(std::lround(screen.height() * screen.pixels_per_metre()));
    auto renderer = render::SceneRenderer::create(scene.definition, width, height);
    if (!renderer) return Error{"screen '" + screen.id() + "': " + renderer.error()};
    auto frustum = render::off_axis_frustum(render::whole_screen(screen), state.eye_now, viewer.near(), viewer.far());
    if (!frustum)
      return Error{"screen '" + screen.id() + "' at frame " + std::to_string(frame) + ": " + frustum.error()};
    renderer.value()->draw(state, 0.0, state.eye_now, frustum.value());
    const std::string folder = (std::filesystem::path(out_dir) / "reference" / screen.id()).string();
    auto written = image::write_frame(folder, frame, renderer.value()->read_linear(), renderer.value()->read_encoded());
    if (!written) return written;
    log.info("screen '{}': {}×{} px → {}", screen.id(), width, height, image::frame_path(folder, frame, "png"));
  }
  return {};
}

}  // namespace optique::master
