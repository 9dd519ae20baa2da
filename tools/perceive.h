#pragma once
// `optique-master perceive`: what an eye that follows motion sees on each screen
// around one frame. Every projector's frames are drawn as its node draws them
// (colour fields and all), put on the screen by the screen simulator, and
// integrated on a retina that moves with the tracked velocity over an exposure,
// each channel only while its field is on (optics/perceive.h). Beside it, the
// ideal: the same eye before a continuous display that shows every colour at
// once, drawn at 32 moments of the exposure.
//   OUT/perceived/<screen>/frame-NNNNNN.{exr,png}        what the eye sees
//   OUT/perceived/<screen>.ideal/frame-NNNNNN.{exr,png}  the ideal
//   OUT/perceived/frame-NNNNNN.json                      the measures

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <spdlog/logger.h>
#include <glm/vec2.hpp>

#include "config/load.h"
#include "image/image.h"
#include "scene_load/load_scene.h"
#include "util/result.h"

namespace optique::tools {

struct PerceiveOptions {
  std::uint64_t frame = 0;  // the exposure is centred on its display time
  // What the eye follows: a scene object by name, or a velocity in screen pixels
  // per frame period (x right, y down).
  std::string object;
  std::optional<glm::dvec2> velocity;
  double exposure = 1.0 / 60.0;  // seconds
  int ideal_moments = 32;
  int samples = 0;  // per projector pixel; 0: each projector's own (render::PipelineOptions)
};

struct PerceivedScreen {
  std::string folder;
  glm::dvec2 velocity{0.0};  // screen pixels per second the eye moved
  // The measures, over the tracked object's neighbourhood (its footprint at the
  // frame, grown by the eye's travel and 4 px; with a velocity, the whole screen).
  int box[4] = {0, 0, 0, 0};  // x0, y0, x1, y1
  bool measured = true;       // false: the tracked object is not on this screen
  double fringe_px = 0.0;     // optics::fringe_width of what the eye sees, across the motion
  double ideal_fringe_px = 0.0;
  double psnr_y_db = 0.0;  // PSNR_Y against the ideal
  image::FloatImage seen;  // what the eye sees, linear RGBA, the screen's raster
  image::FloatImage ideal;
};

// Fails, naming it, on an object the scene does not have, a non-positive
// exposure, or a screen the eye is not in front of.
[[nodiscard]] Result<std::vector<PerceivedScreen>> perceive(const config::LoadedConfig& config,
                                                            const scene::LoadedScene& scene,
                                                            const PerceiveOptions& options, const std::string& out_dir,
                                                            spdlog::logger& log);

// "OBJECT" or "vx,vy" (screen pixels per frame period), as --track takes it.
[[nodiscard]] Result<void> parse_track(const std::string& text, PerceiveOptions& options);

}  // namespace optique::tools
