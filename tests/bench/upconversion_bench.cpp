// Frame-rate up-conversion benchmark (docs/design.md, "Frame-rate up-conversion"):
// the up-conversion paper's scene set, each frame built between key frames
// against the full render of its moment, by method and mode; and speed against
// error on many-lights: key-frame and between-frame cost by ratio.
//
//   optique-bench-upconversion [--out DIR] [--probe RATES]

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "image/compare.h"
#include "image/convert.h"
#include "image/image_io.h"
#include "render/gl_context.h"
#include "up_experiment.h"

namespace {

using namespace optique;
using namespace optique::bench::upconv;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"frame-rate up-conversion: accuracy on the paper's scenes, speed against error"};
  std::string out = "docs/bench";
  std::vector<double> probe;
  int width = 320;
  int height = 240;
  int frames = 24;
  std::vector<std::string> only;
  double screen = 0.0;
  std::string images;
  app.add_option("--images", images,
                 "probe: write each run's hardest frame, its full render and their difference here");
  app.add_option("--screen", screen, "probe: the stage screen's width, metres (0: each scene's)");
  app.add_option("--out", out, "where the table, CSV and plot go");
  app.add_option("--probe", probe, "only print each scene's baseline and motion PSNR_Y at these display rates");
  app.add_option("--frames", frames, "display frames per run");
  app.add_option("--scene", only, "only these scenes");
  bool find_rates = false;
  app.add_flag("--find-rates", find_rates,
               "choose each scene's framing: the screen width and display rate whose average baseline lands "
               "nearest the paper's");
  std::string timing;
  app.add_option("--timing", timing, "only time this built-in scene at 640×360, 4:1 interpolated");
  CLI11_PARSE(app, argc, argv);
  auto context = render::make_headless_context();
  if (!context) {
    std::cerr << "no GL context: " << context.error() << "\n";
    return 1;
  }
  if (!timing.empty()) {
    const StageScene scene{timing, timing, "", 3.2, 60.0, 0.0, 0.0, 0.0};
    for (const Run& run : {Run{config::UpMethod::average, config::UpMode::interpolate, 4, 0.0},
                           Run{config::UpMethod::motion, config::UpMode::interpolate, 4, 0.0},
                           Run{config::UpMethod::motion, config::UpMode::extrapolate, 4, 0.0}}) {
      auto result = measure(scene, run, frames, 640, 360);
      if (!result) {
        std::cerr << result.error() << "\n";
        return 1;
      }
      const SceneResult& r = result.value();
      std::printf(
          "%s %s %s: full %.1f ms, key %.1f ms, between %.1f ms (with a key ahead %.1f), per display frame %.1f ms, "
          "%.2f dB\n",
          timing.c_str(), std::string(config::to_string(run.method)).c_str(),
          std::string(config::to_string(run.mode)).c_str(), r.full_ms, r.key_ms, r.between_ms, r.between_and_ahead_ms,
          r.per_display_frame_ms, r.mean_between_psnr);
    }
    return 0;
  }
  if (find_rates) {
    for (StageScene scene : paper_scenes()) {
      if (!only.empty() && std::find(only.begin(), only.end(), scene.name) == only.end()) continue;
      double best_gap = 1e9;
      StageScene best = scene;
      double best_db = 0.0;
      for (double screen_width : {0.15, 0.25, 0.4, 0.6, 1.0, 1.6, 2.4, 3.2}) {
        for (double rate : {12.0, 15.0, 20.0, 24.0, 30.0, 40.0, 50.0, 60.0, 90.0, 120.0}) {
          scene.screen_width = screen_width;
          scene.frame_rate = rate;
          auto result =
              measure(scene, {config::UpMethod::average, config::UpMode::interpolate, 4, 0.0}, frames, width, height);
          if (!result) {
            std::cerr << scene.name << ": " << result.error() << "\n";
            return 1;
          }
          const double gap = std::abs(result.value().mean_between_psnr - scene.paper_average);
          if (gap < best_gap) {
            best_gap = gap;
            best = scene;
            best_db = result.value().mean_between_psnr;
          }
        }
      }
      std::printf("%-24s screen %.1f m, %5.1f Hz: average %.2f dB (paper %.2f)\n", best.name.c_str(), best.screen_width,
                  best.frame_rate, best_db, best.paper_average);
      std::fflush(stdout);
    }
    return 0;
  }
  for (StageScene scene : paper_scenes()) {
    if (!only.empty() && std::find(only.begin(), only.end(), scene.name) == only.end()) continue;
    if (probe.empty()) probe.push_back(0.0);
    for (double rate : probe) {
      if (rate > 0.0) scene.frame_rate = rate;
      if (screen > 0.0) scene.screen_width = screen;
      std::printf("%-24s %5.1f Hz (paper average %.2f, motion %.2f):", scene.name.c_str(), rate, scene.paper_average,
                  scene.paper_motion);
      for (const Run& run : {Run{config::UpMethod::average, config::UpMode::interpolate, 4, 0.0},
                             Run{config::UpMethod::motion, config::UpMode::interpolate, 4, 0.0},
                             Run{config::UpMethod::motion, config::UpMode::extrapolate, 4, 0.0}}) {
        auto result = measure(scene, run, frames, width, height);
        if (!result) {
          std::printf(" error: %s\n", result.error().c_str());
          return 1;
        }
        if (!images.empty()) {
          const SceneResult& r = result.value();
          const std::string stem = images + "/" + scene.name + "-" + std::to_string(static_cast<int>(rate)) + "-" +
                                   std::string(config::to_string(run.method)) + "-" +
                                   std::string(config::to_string(run.mode));
          (void)image::write_png(stem + "-shown.png", image::encode_srgb(r.hardest_image));
          (void)image::write_png(stem + "-full.png", image::encode_srgb(r.hardest_reference));
          (void)image::write_png(stem + "-difference.png",
                                 image::encode_srgb(image::difference(r.hardest_image, r.hardest_reference, 4.0f)));
        }
        if (std::getenv("OPTIQUE_UP_FRAMES")) {
          for (const FrameResult& f : result.value().frames) {
            std::printf("\n    frame %llu %s %.2f dB unseen %.4f", static_cast<unsigned long long>(f.frame),
                        std::string(up::to_string(f.kind)).c_str(), f.psnr_y, f.unseen_share);
          }
          std::printf("\n");
        }
        std::printf("  %s/%s %.2f dB (key %.1f ms, between %.1f ms, full %.1f ms)",
                    std::string(config::to_string(run.method)).c_str(),
                    std::string(config::to_string(run.mode)).c_str(), result.value().mean_between_psnr,
                    result.value().key_ms, result.value().between_ms, result.value().full_ms);
      }
      std::printf("\n");
      std::fflush(stdout);
    }
  }
  return 0;
}
