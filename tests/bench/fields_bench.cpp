// Colour-field benchmark: what drawing each colour field for its own moment costs
// a single-chip DLP projector's node, by each method, and what it buys the eye
// that follows the moving object. The wall of configs/dlp-pinball.json showing the
// moving square, the pinball and the scrolling stripes; per method: the frame's
// draw time (draw and output pass, finished on the GPU) as ms and as ratios to one
// render and to per-field, side by side in one process, alternating; and
// tools::perceive's fringe width and PSNR_Y against the ideal half a second in, and
// against per-field's perceived image. Writes fields.md, fields.csv and fields.png.
//
//   optique-bench-fields [--out DIR] [--frames N] [--runs R]

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <spdlog/sinks/null_sink.h>

#include "bench_options.h"
#include "clock/clock.h"
#include "config/job.h"
#include "draw_plot.h"
#include "image/compare.h"
#include "image/texture_decode.h"
#include "master/run/run_config.h"
#include "master/run/scene_authority.h"
#include "metrics/distribution.h"
#include "number_text.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"
#include "spread.h"
#include "tools/perceive.h"

namespace {

using namespace optique;

struct Method {
  std::string name;
  config::FieldMethod fields;
  int samples;                      // per pixel
  double velocity_threshold = 0.0;  // px per frame; 0: none
  int gather_samples = 8;           // per field and pixel, along the motion
  bool still_once = true;
};

// The gather as configs/dlp-pinball.json ships it: velocity_threshold 24.
const std::vector<Method> kMethods{
    {"one moment per frame (method off)", config::FieldMethod::off, 1},
    {"per-field, 1 sample per pixel", config::FieldMethod::per_field, 1},
    {"per-field (shipped: 4 samples per pixel, still objects once)", config::FieldMethod::per_field, 4},
    {"per-field, still objects drawn per field too", config::FieldMethod::per_field, 4, 0.0, 8, false},
    {"per-field, blur above velocity_threshold 24", config::FieldMethod::per_field, 4, 24.0},
    {"gather, 4 samples along the motion", config::FieldMethod::gather, 4, 24.0, 4},
    {"gather, 8 along the motion (shipped)", config::FieldMethod::gather, 4, 24.0, 8},
    {"gather, 16 along the motion", config::FieldMethod::gather, 4, 24.0, 16},
    {"gather, 8 along the motion, 1 sample per pixel", config::FieldMethod::gather, 1, 24.0, 8},
    {"up-conversion: each other field from one render by its motion field", config::FieldMethod::up_conversion, 4},
    {"up-conversion, 1 sample per pixel", config::FieldMethod::up_conversion, 1},
};
constexpr std::size_t kPerField = 2;  // the reference for the gather's cost and image

struct Case {
  std::string name;
  std::string scene;    // built-in
  std::string tracked;  // the object the eye follows
  std::string preset = "dlp-brg-120hz";
  int frame_rate = 120;
  bool viewer_walks = false;  // sideways at 3 m/s: everything moves, nothing is drawn once
};

// All on the wall of configs/dlp-pinball.json: 1056×594 px over 4 m; 120 Hz, B R G,
// or the stereo projector used as mono: 60 Hz, six fields in two images.
const std::vector<Case> kCases{
    {"moving square (6 px/frame)", "moving-square", "square"},
    {"pinball (ball 6 px/frame, 8 lights)", "pinball", "ball"},
    {"scrolling stripes (3.3 px/frame)", "scrolling-stripes", "stripes"},
    {"six fields: moving square (12 px per 60 Hz frame)", "moving-square", "square", "dlp-stereo-as-mono", 60},
    {"six fields: pinball (12 px per 60 Hz frame)", "pinball", "ball", "dlp-stereo-as-mono", 60},
    {"six fields: pinball, the viewer walking at 3 m/s", "pinball", "ball", "dlp-stereo-as-mono", 60, true}};

// The moment perceived: half a second into the run (the square halfway across).
std::uint64_t perceived_frame(const Case& c) { return static_cast<std::uint64_t>(c.frame_rate / 2); }

master::RunConfig load(const std::string& scratch, const Case& c, const Method& method) {
  std::ifstream in(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-pinball.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  const auto replace = [&](const std::string& from, const std::string& to) {
    const std::size_t at = json.find(from);
    if (at == std::string::npos) throw std::logic_error("configs/dlp-pinball.json no longer has " + from);
    json.replace(at, from.size(), to);
  };
  replace(R"("builtin": "pinball")", R"("builtin": ")" + c.scene + '"');
  replace(R"("preset": "dlp-brg-120hz")", R"("preset": ")" + c.preset + '"');
  replace(R"("frame_rate": 120)", R"("frame_rate": )" + std::to_string(c.frame_rate));
  std::filesystem::create_directories(scratch);
  const std::string path = scratch + "/" + c.scene + "-" + c.preset + (c.viewer_walks ? "-walking" : "") + ".json";
  std::ofstream(path) << json;
  auto loaded = master::load_run_config(path, image::decode_texture);
  if (!loaded) throw std::runtime_error(loaded.error());
  master::RunConfig run = std::move(loaded).value();
  if (c.viewer_walks) {
    run.config.installation.viewer.path = {{0.0, {-1.5, 1.2, 2.0}}, {1.0, {1.5, 1.2, 2.0}}, {2.0, {-1.5, 1.2, 2.0}}};
  }
  config::ColorFields& fields = run.config.installation.projectors.front().color_fields;
  fields.method = method.fields;
  fields.gather_samples = method.gather_samples;
  fields.velocity_threshold = method.velocity_threshold;
  return run;
}

render::PipelineOptions options_for(const Method& m) {
  render::PipelineOptions options;
  options.samples = m.samples;
  options.still_once = m.still_once;
  return options;
}

using bench::fixed;

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique colour-field benchmark"};
  std::string out = "docs/bench";
  int frames = 24;
  int runs = 5;
  app.option("--out", out, "folder for fields.md, fields.csv and fields.png");
  app.option("--frames", frames, "timed frames per run and method");
  app.option("--runs", runs, "runs; the methods alternate within each");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;
  try {
    std::filesystem::create_directories(out);
    const std::string scratch = out + "/.fields-scratch";
    std::ofstream csv(out + "/fields.csv");
    csv << "renderer,scene,method,run,draw_ms_median,ratio_to_one_moment,ratio_to_per_field,fringe_px,psnr_y_db,"
           "worst_channel_db_vs_per_field\n";
    std::ostringstream table;
    table << "| scene | method | draw ms | × one moment | × per-field | fringe px | PSNR_Y vs ideal dB | "
             "vs per-field dB (worst channel) |\n"
          << "|---|---|---:|---:|---:|---:|---:|---:|\n";
    std::string gl;
    for (const Case& c : kCases) {
      // The eye's view first (each call makes its own GL context).
      std::vector<tools::PerceivedScreen> seen;
      for (const Method& m : kMethods) {
        const master::RunConfig run = load(scratch, c, m);
        tools::PerceiveOptions options;
        options.frame = perceived_frame(c);
        options.object = c.tracked;
        options.samples = m.samples;
        auto logger = std::make_shared<spdlog::logger>("perceive", std::make_shared<spdlog::sinks::null_sink_mt>());
        auto result = tools::perceive(run.config, run.scene, options, scratch + "/perceived", *logger);
        if (!result) throw std::runtime_error(result.error());
        seen.push_back(result.value().front());
      }
      // Each method's perceived image against per-field's, around the tracked object.
      std::vector<double> worst_channel;
      const int* box = seen[kPerField].box;
      const auto around = [&](const image::FloatImage& image) {
        return image::crop(image, box[0], box[1], box[2] - box[0], box[3] - box[1]);
      };
      for (const tools::PerceivedScreen& s : seen) {
        const auto compared = image::compare(around(s.seen), around(seen[kPerField].seen));
        if (!compared) throw std::runtime_error(compared.error());
        worst_channel.push_back(std::min({compared.value().psnr_r, compared.value().psnr_g, compared.value().psnr_b}));
      }
      // Then the draw times, the methods alternating frame by frame.
      auto context = render::make_headless_context();
      if (!context) throw std::runtime_error(context.error());
      gl = context.value()->renderer_name();
      std::vector<master::RunConfig> configs;
      std::vector<std::unique_ptr<render::ProjectorPipeline>> pipelines;
      for (const Method& m : kMethods) {
        configs.push_back(load(scratch, c, m));
        auto pipeline = render::ProjectorPipeline::make(config::job_for(configs.back().config.installation, 0),
                                                        configs.back().scene.definition, options_for(m));
        if (!pipeline) throw std::runtime_error(pipeline.error());
        pipelines.push_back(std::move(pipeline).value());
      }
      const config::Installation& inst = configs.front().config.installation;
      const master::SceneAuthority authority(configs.front().scene.definition.objects, inst.viewer,
                                             inst.master.frame_rate);
      std::vector<std::vector<double>> medians(kMethods.size());
      std::vector<std::vector<double>> ratios(kMethods.size());
      std::vector<std::vector<double>> to_per_field(kMethods.size());
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
        const double per_field = metrics::summarize(times[kPerField]).median();
        for (std::size_t m = 0; m < kMethods.size(); ++m) {
          medians[m].push_back(metrics::summarize(times[m]).median());
          ratios[m].push_back(medians[m].back() / base);
          to_per_field[m].push_back(medians[m].back() / per_field);
          csv << '"' << gl << "\",\"" << c.name << "\",\"" << kMethods[m].name << "\"," << run << ','
              << medians[m].back() << ',' << ratios[m].back() << ',' << to_per_field[m].back() << ','
              << seen[m].fringe_px << ',' << seen[m].psnr_y_db << ',' << worst_channel[m] << '\n';
        }
      }
      for (std::size_t m = 0; m < kMethods.size(); ++m) {
        table << "| " << c.name << " | " << kMethods[m].name << " | " << bench::cell(bench::spread(medians[m]), 2)
              << " | " << bench::cell(bench::spread(ratios[m]), 2) << " | "
              << bench::cell(bench::spread(to_per_field[m]), 2) << " | " << fixed(seen[m].fringe_px, 2) << " | "
              << fixed(seen[m].psnr_y_db, 1) << " | "
              << (std::isfinite(worst_channel[m]) ? fixed(worst_channel[m], 1) : "identical") << " |\n";
      }
    }
    std::filesystem::remove_all(scratch);
    csv.close();
    std::ofstream md(out + "/fields.md");
    md << "# Colour fields: what they cost and what the eye sees\n\n"
       << "Generated by `optique-bench-fields` on " << gl
       << ". The wall of `configs/dlp-pinball.json`: one single-chip DLP projector, 1056×594 px over 4 m at 120 Hz, "
          "fields B R G at −0.2, 0, +0.32 of the frame (0.2 long each), showing three built-in scenes; then the same "
          "wall as the stereo projector used as mono (`dlp-stereo-as-mono`: 60 Hz, six fields in two images, the "
          "second shown half a frame after the first; one moment per frame is then the same image twice), last with "
          "the viewer walking sideways at 3 m/s (everything moves on screen: still objects cannot be drawn once). "
          "On the six-field square the gather is per-field's image to the bit: 12 px per frame moves the square "
          "exactly 2 px from one field to the next, so every shift lands on whole texels. "
          "**Draw ms**: "
          "the node's frame (every pass, then the output pass, finished on the GPU), median per run of "
       << frames << " frames, then the median (min–max) over " << runs
       << " runs; the methods alternate frame by frame in one process. **× one moment**, **× per-field**: per run, "
          "against the frame drawn at one moment (method `off`) and against the shipped per-field. **Fringe, "
          "PSNR_Y**: `optique-master perceive --frame K --track OBJECT` half a second in (one 60 Hz exposure; the "
          "ideal is a display "
          "that shows every colour at every moment, clipped at the projector's white): the spread of the channels' "
          "edges across the motion, and PSNR_Y (0.299 R + 0.587 G + 0.114 B of the channels' PSNRs) against the "
          "ideal around the tracked object. **vs per-field**: the worst channel's PSNR of the perceived image "
          "against per-field's (the gather draws green at its own moment, as per-field does: identical green). "
          "The paper's anchor: its gather cost about 20 % of rendering all six fields of its stereo-as-mono "
          "projector (the six-field rows; with three fields one render is already a third of per-field). Its "
          "gather pass ran on a GPU; here every pass runs on the CPU (llvmpipe), where the gather's many "
          "texture reads per pixel cost far more, relative to drawing the scene, than on a GPU.\n\n"
       << table.str() << "\n![draw time against PSNR_Y per method and scene](fields.png)\n";
    md.close();
    std::cout << table.str();
    return bench::draw_plot(out, "fields") ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-fields: " << e.what() << "\n";
    return 1;
  }
}
