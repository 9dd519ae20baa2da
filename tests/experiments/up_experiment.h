#pragma once
// Frame-rate up-conversion measured (docs/design.md, "Frame-rate up-conversion"):
// a scene of the up-conversion paper's set on a stage, seen through one
// projector, drawn by the pipeline a node builds (ProjectorPipeline with the
// projector's up_conversion) frame after frame as a node draws them, each
// display frame compared with the full render of the same moment as displayed
// (the projector's 8-bit sRGB signal, as the paper compared frame buffers):
// PSNR_Y (the paper's), its 4×4 block classes, and what each kind of frame cost. Shared by
// the benchmark (optique-bench-upconversion) and the gpu test.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "config/up_conversion.h"
#include "image/compare.h"
#include "image/image.h"
#include "up/schedule.h"
#include "util/result.h"

namespace optique::bench::upconv {

// One scene of the set, framed: a screen of `screen_width` metres (4:3) on the
// stage's plane in front of its objects, the viewer 2 m before it, and the
// display rate chosen so that the paper's baseline (the average of the key
// frames around) lands near its number for that scene.
struct StageScene {
  std::string name;     // as reported
  std::string builtin;  // a built-in scene, or
  std::string gltf;     // a glTF file (absolute)
  double screen_width = 1.6;
  double frame_rate = 30.0;
  double start = 0.0;          // seconds: where the sequence starts
  double paper_average = 0.0;  // dB PSNR_Y: the paper's temporal average for it
  double paper_motion = 0.0;   // and its motion-compensated result (0: not in the paper)
  // Config JSON in place of the defaults, for the hard cases: the viewer
  // (default: an eye 2 m before the screen's centre), and more of the scene
  // (e.g. `"light_switches": […]`, after the scene's name).
  std::string viewer_json;
  std::string scene_json;
};

// The paper's set: the built-in cubes, pyramids, wheels and falling ring, and
// the most complex glTF scene optique ships, standing in for its TieFighter.
[[nodiscard]] std::vector<StageScene> paper_scenes();

struct Run {
  config::UpMethod method = config::UpMethod::motion;
  config::UpMode mode = config::UpMode::interpolate;
  int ratio = 4;
  double min_psnr = 0.0;  // 0: the ratio fixed
  bool spread = false;    // key frames drawn a band a frame
  int samples = 1;        // per pixel, both pipelines (multisampling)
};

struct FrameResult {
  std::uint64_t frame = 0;
  up::FrameKind kind = up::FrameKind::full;
  double psnr_y = 0.0;  // against the full render; +infinity where equal
  image::BlockClasses blocks;
  double ms = 0.0;            // what drawing this display frame cost
  double unseen_share = 0.0;  // of its pixels no key frame saw (shaded anew)
  int ratio = 0;              // the schedule's after this frame
};

struct SceneResult {
  std::vector<FrameResult> frames;
  double mean_between_psnr = 0.0;     // over the frames built between key frames
  double mean_shaded_anew = 0.0;      // the share of their pixels shaded anew, averaged
  double block_share[4] = {};         // their 4×4 block classes, averaged
  std::size_t hardest = 0;            // the index of the worst frame between
  double full_ms = 0.0;               // the median full render of the same frames
  double key_ms = 0.0;                // medians per kind (0 where none)
  double between_ms = 0.0;            // a frame between alone
  double between_and_ahead_ms = 0.0;  // one that also drew the next key frame ahead
  // Once started (after the first 2·ratio frames, where interpolation draws key
  // frames at once until the scenes sent ahead reach far enough): the mean
  // display frame, and the costliest, which a frame rate must allow.
  double per_display_frame_ms = 0.0;
  double steady_max_ms = 0.0;
  image::FloatImage hardest_image;  // the hardest frame, its full render and their difference
  image::FloatImage hardest_reference;
};

// Draws `frames` display frames of `scene` from its start at `width` × `height`
// pixels, up-converted as `run` says, each against its full render. Needs a
// current GL context.
[[nodiscard]] Result<SceneResult> measure(const StageScene& scene, const Run& run, int frames, int width, int height);

}  // namespace optique::bench::upconv
