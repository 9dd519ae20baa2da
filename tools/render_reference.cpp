#include "tools/render_reference.h"

#include <cmath>
#include <filesystem>
#include <set>
#include <vector>

#include "geometry/projection.h"
#include "image/convert.h"
#include "image/frame_files.h"
#include "image/texture_decode.h"
#include "master/run/scene_authority.h"
#include "optics/compose.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "scene_load/installation_scene.h"
#include "tools/reference_view.h"
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
  scene::SceneState state = authority.state_at_frame(frame);
  // The assets the journal's applications loaded, read as a node reads them.
  std::vector<scene::LoadedScene> assets;
  if (options.replay != nullptr) {
    std::set<std::string> animated;
    for (const session::JournalAsset& entry : options.replay->assets) {
      auto asset = config::load_asset(entry.asset(), entry.path(), image::decode_texture, entry.sha256());
      if (!asset) return Error{"the replayed journal's asset '" + entry.asset() + "': " + asset.error()};
      if (!asset.value().definition.objects.empty()) animated.insert(entry.asset());
      assets.push_back(std::move(asset).value());
    }
    if (auto replayed =
            master::replay_into(*options.replay, scene.definition, master::live_scene_limits(installation.master.api),
                                installation.master.frame_rate, frame, animated, state);
        !replayed) {
      return Error{"the replayed journal: " + replayed.error()};
    }
  }

  auto context = render::make_headless_context();
  if (!context) return Error{"cannot render: " + context.error()};
  // One reference per screen image, as compose writes one composite: a stereo
  // screen gets one for each eye, seen from that eye.
  for (const ScreenImage& image : screen_images(installation)) {
    const std::string name = screen_image_folder(image.screen->id, image.eye);
    auto view = ReferenceView::make(installation, scene.definition, image, s);
    if (!view) return Error{"screen '" + name + "': " + view.error()};
    for (const scene::LoadedScene& asset : assets) {
      if (auto added = view.value().add_asset(asset.definition); !added) return Error{added.error()};
    }
    auto linear = view.value().draw(state, 0.0);
    if (!linear) return Error{"screen '" + name + "' at frame " + std::to_string(frame) + ": " + linear.error()};
    const std::string folder = (std::filesystem::path(out_dir) / "reference" / name).string();
    // One sample per pixel: the renderer's own encoding; else the averaged light's.
    const image::ByteImage png = s == 1 ? view.value().encoded() : image::encode_srgb(linear.value());
    if (auto written = image::write_frame(folder, frame, linear.value(), png); !written) return written;
    log.info("screen '{}': {}×{} px ({}×{} samples per pixel) → {}", name, view.value().width(), view.value().height(),
             s, s, image::frame_path(folder, frame, "png"));
  }
  return {};
}

}  // namespace optique::tools
