// Colour-field benchmark: what drawing each colour field for its own moment costs
// a single-chip DLP projector's node, and what it buys the eye that follows the
// moving object. configs/dlp-120hz.json (and the same wall at 1056×594, where the
// square crosses 6 px per frame); per method: the frame's draw time (draw and
// output pass, finished on the GPU) as ms and as a ratio to one render, side by
// side in one process, alternating; and tools::perceive's fringe width and PSNR_Y
// against the ideal at frame 60. Writes fields.md, fields.csv and fields.png.
//
//   optique-bench-fields [--out DIR] [--frames N] [--runs R]

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <spdlog/sinks/null_sink.h>

#include "clock/clock.h"
#include "config/job.h"
#include "draw_plot.h"
#include "image/texture_decode.h"
#include "master/run_config.h"
#include "master/scene_authority.h"
#include "metrics/distribution.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"
#include "spread.h"
#include "tools/perceive.h"

namespace {

using namespace optique;

struct Method {
  std::string name;
  config::FieldMethod fields;
  int samples;
};

const std::vector<Method> kMethods{
    {"one moment per frame (method off)", config::FieldMethod::off, 1},
    {"per-field, 1 sample per pixel", config::FieldMethod::per_field, 1},
    {"per-field, 4 samples per pixel (shipped)", config::FieldMethod::per_field, 4},
};

struct Wall {
  std::string name;
  int width, height;  // projector pixels; the screen raster has as many
};

const std::vector<Wall> kWalls{{"640×360 (3.6 px/frame)", 640, 360}, {"1056×594 (6 px/frame)", 1056, 594}};

master::RunConfig load(const Wall& wall, const Method& method) {
  auto loaded =
      master::load_run_config(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-120hz.json", image::decode_texture);
  if (!loaded) throw std::runtime_error(loaded.error());
  master::RunConfig run = std::move(loaded).value();
  config::Installation& inst = run.config.installation;
  config::Projector& p = inst.projectors.front();
  const double scale = static_cast<double>(wall.width) / p.width;
  config::scale_pixels(p, scale);
  if (p.height != wall.height) throw std::logic_error("the wall's pixels are not those of dlp-120hz scaled");
  inst.screens.front().pixels_per_metre *= scale;
  p.color_fields.method = method.fields;
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"optique colour-field benchmark"};
  std::string out = "docs/bench";
  int frames = 24;
  int runs = 5;
  app.add_option("--out", out, "folder for fields.md, fields.csv and fields.png");
  app.add_option("--frames", frames, "timed frames per run and method");
  app.add_option("--runs", runs, "runs; the methods alternate within each");
  CLI11_PARSE(app, argc, argv);
  try {
    std::filesystem::create_directories(out);
    std::ofstream csv(out + "/fields.csv");
    csv << "renderer,wall,method,run,draw_ms_median,ratio_to_one_moment,fringe_px,psnr_y_db\n";
    std::ostringstream table;
    table << "| wall | method | draw ms | × one moment per frame | fringe px | PSNR_Y vs ideal dB |\n"
          << "|---|---|---:|---:|---:|---:|\n";
    std::string gl;
    for (const Wall& wall : kWalls) {
      // The eye's view first (each call makes its own GL context).
      std::vector<tools::PerceivedScreen> seen;
      for (const Method& m : kMethods) {
        const master::RunConfig run = load(wall, m);
        tools::PerceiveOptions options;
        options.frame = 60;
        options.object = "square";
        options.samples = m.samples;
        auto logger = std::make_shared<spdlog::logger>("perceive", std::make_shared<spdlog::sinks::null_sink_mt>());
        const std::string scratch = out + "/.fields-perceived";
        auto result = tools::perceive(run.config, run.scene, options, scratch, *logger);
        std::filesystem::remove_all(scratch);
        if (!result) throw std::runtime_error(result.error());
        seen.push_back(result.value().front());
      }
      // Then the draw times, the methods alternating frame by frame.
      auto context = render::make_headless_context();
      if (!context) throw std::runtime_error(context.error());
      gl = context.value()->renderer_name();
      std::vector<master::RunConfig> configs;
      std::vector<std::unique_ptr<render::ProjectorPipeline>> pipelines;
      for (const Method& m : kMethods) {
        configs.push_back(load(wall, m));
        render::PipelineOptions options;
        options.samples = m.samples;
        auto pipeline = render::ProjectorPipeline::make(config::job_for(configs.back().config.installation, 0),
                                                        configs.back().scene.definition, options);
        if (!pipeline) throw std::runtime_error(pipeline.error());
        pipelines.push_back(std::move(pipeline).value());
      }
      const config::Installation& inst = configs.front().config.installation;
      const master::SceneAuthority authority(configs.front().scene.definition.objects, inst.viewer,
                                             inst.master.frame_rate);
      std::vector<std::vector<double>> medians(kMethods.size());
      std::vector<std::vector<double>> ratios(kMethods.size());
      for (int run = 0; run < runs; ++run) {
        std::vector<std::vector<double>> times(kMethods.size());
        for (int k = -2; k < frames; ++k) {  // two frames unmeasured
          const scene::SceneState state = authority.state_at_frame(static_cast<std::uint64_t>(30 + std::max(k, 0)));
          for (std::size_t i = 0; i < kMethods.size(); ++i) {
            const std::size_t m = (i + static_cast<std::size_t>(k + 2)) % kMethods.size();  // rotate the order
            const clock::Nanos start = clock::monotonic_now();
            if (auto drawn = pipelines[m]->draw_frame(state); !drawn) throw std::runtime_error(drawn.error());
            const clock::Nanos end = clock::monotonic_now();
            if (k >= 0) times[m].push_back(static_cast<double>(end - start) / 1e6);
          }
        }
        const double base = metrics::summarize(times[0]).median();
        for (std::size_t m = 0; m < kMethods.size(); ++m) {
          medians[m].push_back(metrics::summarize(times[m]).median());
          ratios[m].push_back(medians[m].back() / base);
          csv << '"' << gl << "\",\"" << wall.name << "\",\"" << kMethods[m].name << "\"," << run << ','
              << medians[m].back() << ',' << ratios[m].back() << ',' << seen[m].fringe_px << ',' << seen[m].psnr_y_db
              << '\n';
        }
      }
      for (std::size_t m = 0; m < kMethods.size(); ++m) {
        char fringe[32];
        char psnr[32];
        std::snprintf(fringe, sizeof fringe, "%.2f", seen[m].fringe_px);
        std::snprintf(psnr, sizeof psnr, "%.1f", seen[m].psnr_y_db);
        table << "| " << wall.name << " | " << kMethods[m].name << " | " << bench::cell(bench::spread(medians[m]), 2)
              << " | " << bench::cell(bench::spread(ratios[m]), 2) << " | " << fringe << " | " << psnr << " |\n";
      }
    }
    csv.close();
    std::ofstream md(out + "/fields.md");
    md << "# Colour fields: what they cost and what the eye sees\n\n"
       << "Generated by `optique-bench-fields` on " << gl
       << ". `configs/dlp-120hz.json`: one single-chip DLP projector at 120 Hz, fields B R G at −0.2, 0, +0.32 of "
          "the frame (0.2 long each), the white square of `moving-square` crossing the wall; and the same wall at "
          "1056×594 (projector and screen raster), where the square crosses 6 px per frame. **Draw ms**: the node's "
          "frame (every pass, then the output pass, finished on the GPU), median per run of "
       << frames << " frames, then the median (min–max) over " << runs
       << " runs; the methods alternate frame by frame in one process. **× one moment**: per run, against the "
          "frame drawn at one moment (the method `off`). **Fringe, PSNR_Y**: `optique-master perceive --frame 60 "
          "--track square` (one 60 Hz exposure; the ideal is a display that shows every colour at every moment): "
          "the spread of the channels' edges across the motion, and PSNR_Y against the ideal around the square.\n\n"
       << table.str() << "\n![draw time against PSNR_Y per method and wall](fields.png)\n";
    md.close();
    std::cout << table.str();
    return bench::draw_plot(out, "fields") ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-fields: " << e.what() << "\n";
    return 1;
  }
}
