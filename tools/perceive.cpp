#include "tools/perceive.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "config/job.h"
#include "image/compare.h"
#include "image/convert.h"
#include "image/frame_files.h"
#include "master/run/scene_authority.h"
#include "optics/compose.h"
#include "optics/perceive.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"
#include "tools/reference_view.h"
#include "tools/screen_images.h"
#include "util/join.h"

namespace optique::tools {
namespace {

// The ideal's moments are drawn at 4×4 samples per pixel: it must be sharper than
// anything it judges.
constexpr int kIdealSupersample = 4;

// A world point seen from `eye` on the screen, in its raster's pixels (x right,
// y down, as compose and render-reference lay it out); NaN when the screen's
// plane is not ahead of the eye towards it.
glm::dvec2 on_raster(const config::Screen& screen, const glm::dvec3& eye, const glm::dvec3& point) {
  const glm::dvec3 normal = glm::cross(screen.right, screen.up);
  const double t = glm::dot(normal, screen.origin - eye) / glm::dot(normal, point - eye);
  // The screen's plane must lie between the eye and the point, or at least
  // ahead of the eye on the way to it: otherwise the point is not seen through it.
  if (!(t > 0.0)) return glm::dvec2(std::numeric_limits<double>::quiet_NaN());
  const glm::dvec3 hit = eye + t * (point - eye);
  const double x = glm::dot(hit - screen.origin, screen.right);
  const double y = glm::dot(hit - screen.origin, screen.up);
  return {x * screen.pixels_per_metre, (screen.height - y) * screen.pixels_per_metre};
}

// The object's footprint on the raster at `seconds`: the box around every vertex
// of the meshes that ride on it.
std::optional<std::pair<glm::dvec2, glm::dvec2>> footprint(const scene::SceneDefinition& scene, std::uint32_t object,
                                                           const scene::Pose& pose, const config::Screen& screen,
                                                           const glm::dvec3& eye) {
  glm::dvec2 lo(std::numeric_limits<double>::max());
  glm::dvec2 hi(std::numeric_limits<double>::lowest());
  bool any = false;
  for (const scene::Instance& instance : scene.instances) {
    if (instance.object != object) continue;
    const glm::dmat4 model = scene::model_matrix(pose) * instance.transform;
    for (const scene::Vertex& v : scene.meshes[instance.mesh].vertices) {
      const glm::dvec2 p = on_raster(screen, eye, glm::dvec3(model * glm::dvec4(glm::dvec3(v.position), 1.0)));
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;  // not seen through this screen
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      any = true;
    }
  }
  if (!any || lo.x > hi.x) return std::nullopt;
  return std::make_pair(lo, hi);
}

}  // namespace

Result<void> parse_track(const std::string& text, PerceiveOptions& options) {
  const auto comma = text.find(',');
  if (comma == std::string::npos) {
    if (text.empty()) return Error{"--track: give an object's name or vx,vy (screen pixels per frame)"};
    options.object = text;
    options.velocity.reset();
    return {};
  }
  try {
    std::size_t used_x = 0;
    std::size_t used_y = 0;
    const double x = std::stod(text.substr(0, comma), &used_x);
    const double y = std::stod(text.substr(comma + 1), &used_y);
    if (used_x != comma || used_y != text.size() - comma - 1 || !std::isfinite(x) || !std::isfinite(y)) {
      throw std::invalid_argument(text);
    }
    options.velocity = glm::dvec2(x, y);
    return {};
  } catch (const std::exception&) {
    // Not two numbers: an object's name with a comma in it (glTF names may
    // have one); perceive() says so if the scene has no such object.
    options.object = text;
    options.velocity.reset();
    return {};
  }
}

Result<std::vector<PerceivedScreen>> perceive(const config::LoadedConfig& config, const scene::LoadedScene& loaded,
                                              const PerceiveOptions& options, const std::string& out_dir,
                                              spdlog::logger& log) {
  const config::Installation& installation = config.installation;
  const scene::SceneDefinition& scene = loaded.definition;
  if (!(options.exposure > 0.0) || !std::isfinite(options.exposure)) {
    return Error{"the exposure must be > 0 s (got " + std::to_string(options.exposure) + ")"};
  }
  const scene::AnimatedObject* tracked = nullptr;
  if (!options.velocity) {
    const auto found = std::find_if(scene.objects.begin(), scene.objects.end(),
                                    [&](const scene::AnimatedObject& o) { return o.name == options.object; });
    if (found == scene.objects.end()) {
      const std::string names = util::joined(scene.objects, [](const scene::AnimatedObject& o) { return o.name; });
      return Error{"--track: the scene has no object '" + options.object +
                   "' (its moving objects: " + (names.empty() ? "none" : names) + ")" +
                   (options.object.find(',') != std::string::npos
                        ? ", and it is not vx,vy either (two numbers, screen pixels per frame)"
                        : "")};
    }
    tracked = &*found;
  }
  const master::SceneAuthority authority(scene.objects, installation.viewer, installation.master.frame_rate,
                                         master::LightSwitches::from_config(installation.scene));
  const double period = 1.0 / installation.master.frame_rate;
  const double centre = static_cast<double>(options.frame) * period;
  const double open = centre - 0.5 * options.exposure;
  const double close = centre + 0.5 * options.exposure;
  // Every frame shown during the exposure: frame f is on screen from its display
  // time − ½ to + ½ period.
  const auto first = static_cast<std::int64_t>(std::ceil(open / period - 0.5 - 1e-9));
  const auto last = static_cast<std::int64_t>(std::floor(close / period + 0.5 + 1e-9));

  auto context = render::make_headless_context();
  if (!context) return Error{"cannot render: " + context.error()};

  std::vector<PerceivedScreen> results;
  nlohmann::json report = {
      {"frame", options.frame}, {"exposure_s", options.exposure}, {"screens", nlohmann::json::array()}};
  for (const ScreenImage& screen_image : screen_images(installation)) {
    const config::Screen& screen = *screen_image.screen;
    PerceivedScreen result;
    result.folder = screen_image_folder(screen.id, screen_image.eye);
    const int width = optics::screen_pixels(screen.width, screen.pixels_per_metre);
    const int height = optics::screen_pixels(screen.height, screen.pixels_per_metre);
    const glm::dvec3 eye_now = installation.viewer.eye_at(centre);
    // The eye's velocity on this screen's raster, and what to measure over.
    result.box[2] = width;
    result.box[3] = height;
    if (options.velocity) {
      result.velocity = *options.velocity / period;
    } else {
      const auto place = [&](double t) { return on_raster(screen, eye_now, tracked->pose_at(t).position); };
      result.velocity = (place(centre + 0.5 * period) - place(centre - 0.5 * period)) / period;
      if (!std::isfinite(result.velocity.x) || !std::isfinite(result.velocity.y)) {
        // Not seen through this screen: a still eye here, and nothing to measure.
        result.velocity = glm::dvec2(0.0);
        result.box[2] = result.box[0];
      } else if (const auto box = footprint(scene, tracked->id, tracked->pose_at(centre), screen, eye_now)) {
        const double grow = 0.5 * glm::length(result.velocity) * options.exposure + 4.0;
        const auto inside = [](double v, int size) { return static_cast<int>(std::clamp(v, 0.0, double(size))); };
        result.box[0] = inside(std::floor(box->first.x - grow), width);
        result.box[1] = inside(std::floor(box->first.y - grow), height);
        result.box[2] = inside(std::ceil(box->second.x + grow), width);
        result.box[3] = inside(std::ceil(box->second.y + grow), height);
      }
    }
    const optics::Exposure exposure{centre, options.exposure, result.velocity};
    // It takes a while on a software rasterizer: each step is said as it starts.
    log.info("screen '{}': drawing frames {}…{} of its {} projector(s), the eye following {:.2f}, {:.2f} px per frame",
             result.folder, std::max<std::int64_t>(first, 0), last, screen_image.projectors.size(),
             result.velocity.x * period, result.velocity.y * period);

    // What the projectors put on the screen, frame by frame, field by field.
    std::deque<image::FloatImage> lights;  // the emissions point into it
    std::vector<optics::Emission> emissions;
    double white = 0.0;  // the most light one projector of this screen shows
    for (const config::Projector* projector : screen_image.projectors) {
      white = std::max(white, optics::ProjectorModel(projector->response).white());
      const std::size_t index = static_cast<std::size_t>(projector - installation.projectors.data());
      const config::ProjectorJob job = config::job_for(installation, index);
      render::PipelineOptions pipeline_options;
      pipeline_options.samples = options.samples;
      auto pipeline = render::ProjectorPipeline::make(job, scene, pipeline_options);
      if (!pipeline) return Error{pipeline.error()};
      const geometry::ProjectorGeometry geometry = projector->geometry();
      optics::ComposeOptions compose;
      compose.pixels_per_metre = screen.pixels_per_metre;
      for (std::int64_t f = first; f <= last; ++f) {
        if (f < 0) continue;  // before the run's first frame: nothing was shown
        const double shown = static_cast<double>(f) * period;
        // Each of the frame's images (a stereo projector used as mono shows
        // two) emits during its own fields.
        const auto emit = [&](int image) {
          const image::FloatImage emitted = pipeline.value()->renderer().output().read_linear();
          const optics::ProjectedImage placed{&geometry, &emitted};
          lights.push_back(optics::compose_screen({&placed, 1}, screen.width, screen.height, compose));
          if (projector->color_fields.fields.empty()) {
            emissions.push_back({&lights.back(), true, true, true, shown - 0.5 * period, shown + 0.5 * period, 1.0});
            return;
          }
          for (const config::ColorField& field : projector->color_fields.fields) {
            if (field.image != image) continue;
            optics::Emission e{&lights.back(), field.channel == config::Channel::red,
                               field.channel == config::Channel::green, field.channel == config::Channel::blue};
            e.start = shown + field.start() * period;
            e.end = shown + field.end() * period;
            e.on_fraction = projector->color_fields.on_share(field.channel);
            emissions.push_back(e);
          }
        };
        if (auto drawn = pipeline.value()->draw_frame(authority.state_at_frame(static_cast<std::uint64_t>(f)), emit);
            !drawn) {
          return Error{"projector '" + projector->id + "' at frame " + std::to_string(f) + ": " + drawn.error()};
        }
      }
    }
    const image::FloatImage seen = optics::perceive(emissions, width, height, exposure);

    // The ideal: the same eye before a display that shows every colour at every
    // moment, at `ideal_moments` moments of the exposure — as bright as the
    // projectors can be (a highlight beyond their white is clipped there too, and
    // is no error of the fields).
    log.info("screen '{}': the ideal, {} moments of the exposure", result.folder, options.ideal_moments);
    auto view = ReferenceView::make(installation, scene, screen_image, kIdealSupersample);
    if (!view) return Error{"screen '" + result.folder + "': " + view.error()};
    std::vector<image::FloatImage> moments;
    moments.reserve(static_cast<std::size_t>(options.ideal_moments));
    std::vector<optics::Emission> continuous;
    const double step = options.exposure / options.ideal_moments;
    for (int m = 0; m < options.ideal_moments; ++m) {
      const double t = open + (m + 0.5) * step;
      const double nearest = std::max(0.0, std::round(t / period));
      auto light =
          view.value().draw(authority.state_at_frame(static_cast<std::uint64_t>(nearest)), t / period - nearest);
      if (!light) return Error{"screen '" + result.folder + "': " + light.error()};
      moments.push_back(std::move(light).value());
      image::FloatImage& moment = moments.back();
      const auto channels = static_cast<std::size_t>(moment.channels);
      for (std::size_t i = 0; i < moment.pixels.size(); ++i) {
        if (i % channels < 3) moment.pixels[i] = std::min(moment.pixels[i], static_cast<float>(white));
      }
      continuous.push_back({&moments.back(), true, true, true, t - 0.5 * step, t + 0.5 * step, 1.0});
    }
    const image::FloatImage ideal = optics::perceive(continuous, width, height, exposure);

    // The measures, over the neighbourhood.
    const auto crop = [&](const image::FloatImage& image) {
      return image::crop(image, result.box[0], result.box[1], result.box[2] - result.box[0],
                         result.box[3] - result.box[1]);
    };
    // On a screen where the tracked object is not, there is nothing to measure.
    result.measured = result.box[2] > result.box[0] && result.box[3] > result.box[1];
    if (result.measured) {
      // Fringes lie across the motion: measured along its main axis.
      const bool along_x = std::abs(result.velocity.x) >= std::abs(result.velocity.y);
      result.fringe_px =
          optics::fringe_width(seen, result.box[0], result.box[1], result.box[2], result.box[3], along_x);
      result.ideal_fringe_px =
          optics::fringe_width(ideal, result.box[0], result.box[1], result.box[2], result.box[3], along_x);
      auto compared = image::compare(crop(seen), crop(ideal));
      if (!compared) return Error{compared.error()};
      result.psnr_y_db = compared.value().psnr_y_weighted;
    }

    const std::string folder = (std::filesystem::path(out_dir) / "perceived" / result.folder).string();
    if (auto written = image::write_frame(folder, options.frame, seen, image::encode_srgb(seen)); !written) {
      return Error{written.error()};
    }
    if (auto written = image::write_frame(folder + ".ideal", options.frame, ideal, image::encode_srgb(ideal));
        !written) {
      return Error{written.error()};
    }
    const std::string png = image::frame_path(folder, options.frame, "png");
    const glm::dvec2 per_frame = result.velocity * period;
    nlohmann::json entry = {{"screen", result.folder},
                            {"eye_velocity_px_per_frame", {per_frame.x, per_frame.y}},
                            {"measured", result.measured}};
    if (result.measured) {
      // Which pixels the numbers are over: a velocity names no object, so the
      // whole screen, still background and all (PSNR_Y far higher than around
      // a moving object at the same speed).
      const std::string over =
          options.velocity
              ? fmt::format("the whole screen, {}×{} px", result.box[2] - result.box[0], result.box[3] - result.box[1])
              : fmt::format("'{}' and its motion, {}×{} px", options.object, result.box[2] - result.box[0],
                            result.box[3] - result.box[1]);
      log.info(
          "screen '{}': the eye at ({:.1f}, {:.1f}) px/frame over {:.4f} s: colour fringes {:.2f} px (ideal "
          "{:.2f}), PSNR_Y {:.2f} dB against the ideal, over {} → {}",
          result.folder, per_frame.x, per_frame.y, options.exposure, result.fringe_px, result.ideal_fringe_px,
          result.psnr_y_db, over, png);
      entry["measured_over"] = options.velocity ? "screen" : "object";
      entry["box"] = {result.box[0], result.box[1], result.box[2], result.box[3]};
      entry["fringe_px"] = result.fringe_px;
      entry["ideal_fringe_px"] = result.ideal_fringe_px;
      entry["psnr_y_db"] = std::isfinite(result.psnr_y_db) ? nlohmann::json(result.psnr_y_db) : nlohmann::json("inf");
    } else {
      log.info("screen '{}': '{}' is not on it at frame {}: nothing measured → {}", result.folder, options.object,
               options.frame, png);
    }
    report["screens"].push_back(entry);
    result.seen = seen;
    result.ideal = ideal;
    results.push_back(std::move(result));
  }
  if (!options.object.empty()) report["tracked_object"] = options.object;
  const std::string json =
      image::frame_path((std::filesystem::path(out_dir) / "perceived").string(), options.frame, "json");
  if (!(std::ofstream(json) << report.dump(2) << "\n")) return Error{"cannot write " + json};
  return results;
}

}  // namespace optique::tools
