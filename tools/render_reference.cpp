#include "tools/render_reference.h"

#include <cmath>
#include <filesystem>

#include "geometry/projection.h"
#include "image/convert.h"
#include "image/frame_files.h"
#include "master/scene_authority.h"
#include "optics/compose.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "tools/screen_images.h"

namespace optique::tools {

Result<void> render_reference(const config::LoadedConfig& config, const scene::LoadedScene& scene, std::uint64_t frame,
                              const std::string& out_dir, spdlog::logger& log, const ReferenceOptions& options) {
  if (options.supersample < 1) {
    return Error{"the supersample factor must be at least 1, not " + std::to_string(options.supersample)};
  }
  const int s = options.supersample;
  const auto& installation = config.installation;
  const master::SceneAuthority authority(scene.definition.objects, installation.viewer, installation.master.frame_rate,
                                         master::LightSwitches::from_config(installation.scene));
  const scene::SceneState state = authority.state_at_frame(frame);

  auto context = render::make_headless_context();
  if (!context) return Error{"cannot render: " + context.error()};
  const config::Viewer& viewer = installation.viewer;
  // One reference per screen image, as compose writes one composite: a stereo
  // screen gets one for each eye, seen from that eye.
  for (const ScreenImage& image : screen_images(installation)) {
    const config::Screen& screen = *image.screen;
    const std::string name = screen_image_folder(screen.id, image.eye);
    // The composite's raster, so the two compare pixel for pixel.
    const int width = optics::screen_pixels(screen.width, screen.pixels_per_metre);
    const int height = optics::screen_pixels(screen.height, screen.pixels_per_metre);
    auto renderer = render::SceneRenderer::create(scene.definition, width * s, height * s);
    if (!renderer) return Error{"screen '" + name + "': " + renderer.error()};
    const glm::dvec3 eye = geometry::eye_position(state.eye_now, viewer.head_right, viewer.eye_separation, image.eye);
    auto frustum = geometry::off_axis_frustum(screen.world(), eye, viewer.near, viewer.far);
    if (!frustum) return Error{"screen '" + name + "' at frame " + std::to_string(frame) + ": " + frustum.error()};
    renderer.value()->draw(state, 0.0, eye, frustum.value());
    const std::string folder = (std::filesystem::path(out_dir) / "reference" / name).string();
    Result<void> written;
    if (s == 1) {
      written = image::write_frame(folder, frame, renderer.value()->read_rendered(), renderer.value()->read_encoded());
    } else {
      const image::FloatImage linear = image::box_downsample(renderer.value()->read_rendered(), s);
      written = image::write_frame(folder, frame, linear, image::encode_srgb(linear));
    }
    if (!written) return written;
    log.info("screen '{}': {}×{} px ({}×{} samples per pixel) → {}", name, width, height, s, s,
             image::frame_path(folder, frame, "png"));
  }
  return {};
}

}  // namespace optique::tools
