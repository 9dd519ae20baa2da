// Render benchmark: the time one node spends drawing a frame (draw + encode,
// finished on the GPU) for built-in scenes and projector resolutions, on
// whatever GL this machine has (llvmpipe without a GPU). In one process, so
// the numbers are the renderer's own, without cluster traffic or other nodes.
//
//   optique-bench-render [--out DIR] [--frames N] [--repeats R]

#include <filesystem>
#include <fstream>
#include <iostream>

#include "bench_options.h"
#include "clock/clock.h"
#include "geometry/projection.h"
#include "metrics/distribution.h"
#include "render/gl_context.h"
#include "render/scene_renderer.h"
#include "scene/builtin.h"
#include "spread.h"

namespace {

using namespace optique;

struct Case {
  std::string scene;
  int width;
  int height;
};

// Frame times in ms for `frames` frames of `c`, seen from (0, 1.6, 2) through the
// single-wall screen (4 × 2.25 m at z = 0), animated objects moving as the
// master would move them at 60 Hz.
std::vector<double> frame_times(const Case& c, int frames) {
  auto definition = scene::builtin_scene(c.scene);
  if (!definition) throw std::runtime_error(definition.error());
  auto renderer = render::SceneRenderer::create(definition.value(), c.width, c.height);
  if (!renderer) throw std::runtime_error(renderer.error());
  geometry::WorldRect wall;
  wall.lower_left = {-2.0, 0.0, 0.0};
  wall.width = 4.0;
  wall.height = 2.25;
  const glm::dvec3 eye(0.0, 1.6, 2.0);
  const auto frustum = geometry::off_axis_frustum(wall, eye, 0.05, 100.0).value();
  std::vector<double> times;
  for (int k = -3; k < frames; ++k) {  // three unmeasured frames first
    scene::SceneState state;
    const double t = std::max(k, 0) / 60.0;
    for (const auto& object : definition.value().objects) {
      state.objects[object.id] = {object.pose_at(t), object.pose_at(t + 1.0 / 60.0)};
    }
    const clock::Nanos start = clock::monotonic_now();
    renderer.value()->draw(state, {0.0, eye, frustum});
    const clock::Nanos end = clock::monotonic_now();
    if (k >= 0) times.push_back(static_cast<double>(end - start) / 1e6);
  }
  return times;
}

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique render benchmark"};
  std::string out = "docs/bench";
  int frames = 100;
  int repeats = 3;
  app.option("--out", out, "folder for render.md and render.csv");
  app.option("--frames", frames, "measured frames per run");
  app.option("--repeats", repeats, "runs per case; the table shows the median and the min–max over runs");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  auto context = render::make_headless_context();
  if (!context) {
    std::cerr << "optique-bench-render: " << context.error() << "\n";
    return 1;
  }
  const std::string gl = context.value()->renderer_name();
  const std::vector<Case> cases{
      {"cubes", 320, 180}, {"cubes", 1280, 720}, {"many-lights", 320, 180}, {"many-lights", 1280, 720}};
  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/render.csv");
  csv << "renderer,scene,width,height,repeat,frames,median_ms,p99_ms\n";
  std::ostringstream table;
  table << "| scene | resolution | frame time median ms | p99 ms | frames/s (from median) |\n"
        << "|---|---|---:|---:|---:|\n";
  for (const Case& c : cases) {
    std::vector<double> medians;
    std::vector<double> p99s;
    for (int r = 0; r < repeats; ++r) {
      const auto summary = metrics::summarize(frame_times(c, frames));
      medians.push_back(summary.median());
      p99s.push_back(summary.p99());
      csv << '"' << gl << "\"," << c.scene << ',' << c.width << ',' << c.height << ',' << r << ',' << frames << ','
          << summary.median() << ',' << summary.p99() << '\n';
    }
    const bench::Spread median = bench::spread(medians);
    table << "| " << c.scene << " | " << c.width << "×" << c.height << " | " << bench::cell(median, 2) << " | "
          << bench::cell(bench::spread(p99s), 2) << " | " << static_cast<int>(1000.0 / median.median) << " |\n";
  }
  std::ofstream md(out + "/render.md");
  md << "Render benchmark on " << gl << ": " << frames << " frames per run, " << repeats
     << " runs per row; each cell is the median over runs with the min–max in brackets. Frame time = draw + "
        "encode, finished (glFinish).\n\n"
     << table.str();
  std::cout << "renderer: " << gl << "\n" << table.str();
  return 0;
}
