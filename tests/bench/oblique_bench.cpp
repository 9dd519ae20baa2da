// Single pass against two passes for keystoned projectors (Raskar, "Immersive Planar
// Display using Roughly Aligned Projectors"): the
// same frames drawn both ways in one run, alternating, for each projector of an
// installation. Frame time of each, and the PSNR of each against a 4×-supersampled
// image of the same projector (drawn at 4× its pixels with the exact single-pass
// projection and box-filtered down: the average of the scene over each pixel's
// footprint, which any exact method converges to). The paper claims the single
// pass is free and avoids the resampling blur of the two-pass warp.
//
//   optique-bench-oblique [--config FILE] [--out DIR] [--frames N] [--repeats R]

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "bench_options.h"
#include "clock/clock.h"
#include "scene_load/installation_scene.h"
#include "config/job.h"
#include "config/load.h"
#include "draw_plot.h"
#include "image/compare.h"
#include "image/convert.h"
#include "image/texture_decode.h"
#include "master/run/scene_authority.h"
#include "metrics/distribution.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"
#include "scene_load/load_scene.h"
#include "spread.h"

namespace {

using namespace optique;

constexpr int kSupersample = 4;

// One way to draw a projector: its pipeline, built as its node builds it but for
// the method and without blend weights (the comparison is of methods), as a
// 16-bit projector (of methods, not of 8-bit steps).
struct Method {
  std::unique_ptr<render::ProjectorPipeline> pipeline;
  [[nodiscard]] const render::ProjectorView& view() const { return pipeline->view(); }
  [[nodiscard]] image::FloatImage light() const { return pipeline->renderer().output().read_linear(); }
};

Method make_method(config::ProjectorJob job, const scene::SceneDefinition& scene, render::RenderMethod how,
                   double texture_density = 0.0) {
  config::Projector& projector = job.installation.projectors[job.projector];
  projector.rendering = how;
  projector.response = {};
  projector.response.bits = 16;
  auto pipeline =
      render::ProjectorPipeline::make(job, scene, {.two_pass_pixels_per_metre = texture_density, .blend = false});
  if (!pipeline) throw std::runtime_error(pipeline.error());
  return {std::move(pipeline).value()};
}

// Draws one frame; returns the time to a finished image, in ms.
double draw(Method& m, const scene::SceneState& state) {
  const clock::Nanos start = clock::monotonic_now();
  if (auto drawn = m.pipeline->draw(state); !drawn) throw std::runtime_error(drawn.error());
  return static_cast<double>(clock::monotonic_now() - start) / 1e6;
}

// The pixels whose centre lands in the screen's usable area: outside it the
// projector is masked, and the methods differ by construction.
std::vector<bool> usable_pixels(const geometry::ProjectorGeometry& geometry, const geometry::ScreenRect& usable) {
  std::vector<bool> inside;
  for (int y = 0; y < geometry.height(); ++y) {
    for (int x = 0; x < geometry.width(); ++x) {
      inside.push_back(usable.contains(geometry.to_screen(glm::dvec2(x + 0.5, y + 0.5))));
    }
  }
  return inside;
}

// PSNR of luma over the usable pixels, peak 1 (linear light).
double psnr_luma(const image::FloatImage& a, const image::FloatImage& b, const std::vector<bool>& inside) {
  return image::psnr_luma_where(a, b, [&](int x, int y) { return inside[static_cast<std::size_t>(y) * a.width + x]; });
}

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique oblique-projection benchmark: single pass vs two passes"};
  std::string config_path = std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-oblique-3.json";
  std::string out = "docs/bench";
  int frames = 12;
  int repeats = 3;
  app.option("--config", config_path, "installation with keystoned projectors (fixed eye)");
  app.option("--out", out, "folder for oblique.md and oblique.csv");
  app.option("--frames", frames, "frames per run (0.25 s of animation apart)");
  app.option("--repeats", repeats, "runs; times are medians per run, the table their median and min–max");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  try {
    auto loaded = config::load_installation(config_path);
    if (!loaded) throw std::runtime_error(loaded.error());
    const config::Installation& installation = loaded.value().installation;
    if (installation.viewer.moves()) throw std::runtime_error("the bench needs a fixed viewer eye");
    auto scene = config::load_scene(installation, image::decode_texture);
    if (!scene) throw std::runtime_error(scene.error());
    const auto& definition = scene.value().definition;
    // Frames 0.25 s of animation apart, as the master would step them at 4 Hz.
    const master::SceneAuthority authority(definition.objects, installation.viewer, 4.0);
    auto context = render::make_headless_context();
    if (!context) throw std::runtime_error(context.error());
    const std::string gl = context.value()->renderer_name();

    std::filesystem::create_directories(out);
    std::ofstream csv(out + "/oblique.csv");
    csv << "renderer,projector,run,frame,single_ms,two_ms,two_equal_ms,single_psnr_db,two_psnr_db,two_equal_psnr_db\n";
    std::ostringstream table;
    table << "| projector | k | method | texture | frame ms | time ratio to single | PSNR dB |\n"
          << "|---|---:|---|---|---:|---:|---:|\n";
    // One point per (projector, method): median frame time, median PSNR.
    for (std::size_t index = 0; index < installation.projectors.size(); ++index) {
      const config::Projector& projector = installation.projectors[index];
      const config::ProjectorJob job = config::job_for(installation, index);
      const geometry::ProjectorGeometry geometry = projector.geometry();
      Method single = make_method(job, definition, render::RenderMethod::single_pass);
      Method two = make_method(job, definition, render::RenderMethod::two_pass);
      // Two passes with as many texels as the projector has pixels: less work, more blur.
      const geometry::ScreenRect& r = two.view().oblique().bounds;
      const double equal_density =
          std::sqrt(static_cast<double>(geometry.width()) * geometry.height() / (r.width() * r.height()));
      Method two_equal = make_method(job, definition, render::RenderMethod::two_pass, equal_density);
      const std::vector<bool> inside = usable_pixels(geometry, job.screen().area());
      // The reference: the same projector with kSupersample² as many pixels.
      const config::ProjectorJob fine = config::supersampled(job, kSupersample);
      Method reference = make_method(fine, definition, render::RenderMethod::single_pass);

      std::vector<double> single_medians, two_medians, equal_medians, ratios, equal_ratios, single_psnrs, two_psnrs,
          equal_psnrs;
      for (int run = 0; run < repeats; ++run) {
        std::vector<double> single_ms, two_ms, equal_ms;
        for (int k = -2; k < frames; ++k) {  // two unmeasured frames first
          const scene::SceneState state = authority.state_at_frame(static_cast<std::uint64_t>(std::max(k, 0)));
          // Rotate which goes first, so none always follows another.
          std::array<Method*, 3> order{&single, &two, &two_equal};
          std::rotate(order.begin(), order.begin() + (k + 3) % 3, order.end());
          std::map<Method*, double> ms;
          for (Method* m : order) ms[m] = draw(*m, state);
          if (k < 0) continue;
          single_ms.push_back(ms[&single]);
          two_ms.push_back(ms[&two]);
          equal_ms.push_back(ms[&two_equal]);
          std::array<double, 3> psnr{};
          if (run == 0) {  // the images do not change between runs
            draw(reference, state);
            const image::FloatImage ideal = image::box_downsample(reference.light(), kSupersample);
            psnr = {psnr_luma(single.light(), ideal, inside), psnr_luma(two.light(), ideal, inside),
                    psnr_luma(two_equal.light(), ideal, inside)};
            single_psnrs.push_back(psnr[0]);
            two_psnrs.push_back(psnr[1]);
            equal_psnrs.push_back(psnr[2]);
          }
          csv << '"' << gl << "\"," << projector.id << ',' << run << ',' << k << ',' << ms[&single] << ',' << ms[&two]
              << ',' << ms[&two_equal];
          for (double p : psnr) csv << ',' << (run == 0 ? std::to_string(p) : "");
          csv << '\n';
        }
        const double sm = metrics::summarize(single_ms).median();
        single_medians.push_back(sm);
        two_medians.push_back(metrics::summarize(two_ms).median());
        equal_medians.push_back(metrics::summarize(equal_ms).median());
        ratios.push_back(two_medians.back() / sm);
        equal_ratios.push_back(equal_medians.back() / sm);
      }
      auto row = [&](const char* method, const Method& m, const std::vector<double>& times,
                     const std::vector<double>& ratio, const std::vector<double>& psnrs) {
        char k[32];
        std::snprintf(k, sizeof k, "%.3f", single.view().oblique().depth_scale);
        table << "| " << projector.id << " | " << k << " | " << method << " | "
              << (m.view().method() == render::RenderMethod::two_pass
                      ? std::to_string(m.view().render_width()) + "×" + std::to_string(m.view().render_height())
                      : std::string("–"))
              << " | " << bench::cell(bench::spread(times), 2) << " | "
              << (ratio.empty() ? std::string("1") : bench::cell(bench::spread(ratio), 2)) << " | "
              << bench::cell(bench::spread(psnrs), 1) << " |\n";
      };
      row("single pass", single, single_medians, {}, single_psnrs);
      row("two passes, texels at the densest pixel pitch", two, two_medians, ratios, two_psnrs);
      row("two passes, as many texels as pixels", two_equal, equal_medians, equal_ratios, equal_psnrs);
    }
    std::ofstream md(out + "/oblique.md");
    md << "Single pass vs two passes on " << gl << ", " << config_path.substr(config_path.rfind('/') + 1) << ", "
       << frames << " frames × " << repeats
       << " runs, alternating. Times: median per run, then median (min–max) over runs; ratio per run. PSNR (luma, "
          "linear light, over the screen's usable area) against the 4×-supersampled image of the same projector: "
          "median (min–max) over frames.\n\n"
       << table.str()
       << "\n![frame time against PSNR per projector: single pass and the two two-pass variants](oblique.png)\n";
    md.close();
    csv.close();
    std::cout << "renderer: " << gl << "\n" << table.str();
    if (!bench::draw_plot(out, "oblique")) return 1;
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-oblique: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
