#include "tools/compose.h"

#include <algorithm>
#include <filesystem>

#include "image/convert.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "optics/blend.h"
#include "optics/compose.h"
#include "optics/defocus.h"
#include "optics/projector_model.h"
#include "tools/screen_images.h"
#include "util/join.h"

namespace optique::tools {
namespace {

// The signal the node sent its projector: the simulator turns it into light with
// the projector's model, as the projector would.
std::string capture_path(const std::string& captures_dir, const config::Projector& projector, std::uint64_t frame) {
  return image::frame_path((std::filesystem::path(captures_dir) / projector.id).string(), frame, "png");
}

Result<image::FloatImage> read_capture(const std::string& path, const config::Projector& projector) {
  auto read = image::read_image(path);
  if (!read) return Error{"projector '" + projector.id + "': " + read.error()};
  image::FloatImage capture = std::move(read).value();
  if (capture.width != projector.width || capture.height != projector.height) {
    return Error{"projector '" + projector.id + "': capture " + path + " is " + std::to_string(capture.width) + "×" +
                 std::to_string(capture.height) + " px, but the projector is " + std::to_string(projector.width) + "×" +
                 std::to_string(projector.height) + " px (captures from another config?)"};
  }
  if (capture.channels < 3) {
    return Error{"projector '" + projector.id + "': capture " + path + " has " + std::to_string(capture.channels) +
                 " channel(s); expected RGB or RGBA"};
  }
  return optics::emitted_image(capture, optics::ProjectorModel(projector.response));
}

// Share of the raster's pixel centres inside some projector's lit quad.
double covered_share(const std::vector<geometry::ProjectorGeometry>& geometries, const config::Screen& screen,
                     int width, int height) {
  if (width <= 0 || height <= 0) return 0.0;
  const optics::BlendField field(geometries, screen.area(), 0.0);
  const double ppm = screen.pixels_per_metre;
  std::size_t lit = 0;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (field.covered(glm::dvec2((u + 0.5) / ppm, screen.height - (v + 0.5) / ppm))) ++lit;
    }
  }
  return static_cast<double>(lit) / (static_cast<double>(width) * height);
}

}  // namespace

Result<ComposeSummary> compose_frame(const config::LoadedConfig& config, std::uint64_t frame,
                                     const std::string& captures_dir, const std::string& out_dir, spdlog::logger& log) {
  std::vector<ScreenImage> groups = screen_images(config.installation);
  // A screen no projector lights has nothing to compose.
  std::erase_if(groups, [](const ScreenImage& image) { return image.projectors.empty(); });
  if (groups.empty()) return Error{"the installation has no projectors on its screens: nothing to compose"};

  // Every capture must be there before anything is written: a half-composed
  // frame is worse than none.
  std::vector<std::string> missing;
  for (const ScreenImage& group : groups) {
    for (const config::Projector* p : group.projectors) {
      const std::string path = capture_path(captures_dir, *p, frame);
      if (!std::filesystem::is_regular_file(path)) missing.push_back(path);
    }
  }
  if (!missing.empty()) {
    std::string message = "no capture of frame " + std::to_string(frame) + ": " + missing.front() + " does not exist";
    if (missing.size() > 1) message += " (and " + std::to_string(missing.size() - 1) + " more)";
    message += "; was frame " + std::to_string(frame) +
               " captured? Run the cluster with --capture-every N so that frame " + std::to_string(frame) +
               " is a multiple of N, and pass the folder that holds <projector-id>/frame-NNNNNN.png";
    return Error{message};
  }

  ComposeSummary summary;
  summary.frame = frame;
  for (const ScreenImage& group : groups) {
    const config::Screen& screen = *group.screen;
    std::vector<geometry::ProjectorGeometry> geometries;
    std::vector<image::FloatImage> captures;
    ComposedScreen composed;
    composed.folder = screen_image_folder(screen.id, group.eye);
    composed.screen = screen.id;
    composed.eye = group.eye;
    for (const config::Projector* p : group.projectors) {
      auto capture = read_capture(capture_path(captures_dir, *p, frame), *p);
      if (!capture) return Error{capture.error()};
      geometries.push_back(p->geometry());
      captures.push_back(std::move(capture).value());
      composed.projectors.push_back(p->id);
    }
    // Sharp projectors land together; a defocused one lands alone and its optics
    // blur what it throws by its circle of confusion, in screen pixels.
    std::vector<optics::ProjectedImage> sharp;
    std::vector<std::pair<optics::ProjectedImage, double>> blurred;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
      const optics::ProjectedImage projected{&geometries[i], &captures[i]};
      if (group.projectors[i]->content.role == config::ContentRole::defocus) {
        blurred.emplace_back(projected, group.projectors[i]->content.blur_radius);
      } else {
        sharp.push_back(projected);
      }
      composed.subsamples =
          std::max(composed.subsamples, optics::subsamples_for(geometries[i], screen.pixels_per_metre));
    }
    optics::ComposeOptions options;
    options.pixels_per_metre = screen.pixels_per_metre;
    image::FloatImage linear = optics::compose_screen(sharp, screen.width, screen.height, options);
    for (const auto& [projected, radius] : blurred) {
      const image::FloatImage thrown = optics::disc_blur(
          optics::compose_screen(std::span(&projected, 1), screen.width, screen.height, options), radius);
      for (std::size_t k = 0; k < linear.pixels.size(); ++k) {
        if (k % 4 != 3) linear.pixels[k] += thrown.pixels[k];
      }
    }
    composed.width = linear.width;
    composed.height = linear.height;
    composed.covered = covered_share(geometries, screen, linear.width, linear.height);

    const std::string folder = (std::filesystem::path(out_dir) / "screens" / composed.folder).string();
    if (auto written = image::write_frame(folder, frame, linear, image::encode_srgb(linear)); !written) {
      return Error{"screen '" + screen.id + "': " + written.error()};
    }
    composed.exr_path = image::frame_path(folder, frame, "exr");
    composed.png_path = image::frame_path(folder, frame, "png");
    const std::string names = util::joined(composed.projectors);
    log.info("screen '{}' ({}): {}×{} px from {} projector(s) [{}], {}×{} subsamples, {:.1f}% lit → {}", screen.id,
             config::to_string(group.eye), composed.width, composed.height, composed.projectors.size(), names,
             composed.subsamples, composed.subsamples, 100.0 * composed.covered, composed.png_path);
    summary.screens.push_back(std::move(composed));
  }
  return summary;
}

}  // namespace optique::tools
