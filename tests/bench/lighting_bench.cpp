// The lighting split across stacked projectors (Majumder & Welch, "Computer
// Graphics Optique"; docs/design.md, "The lighting split"): each node draws some of the scene's point lights,
// one also the ambient and emissive terms, and the projectors' light adds up to
// the full render on the screen. What the cluster buys: the frame time of the
// slowest node against one node drawing everything; what it costs: the error of
// the optical sum, before and after each projector's 8-bit quantization.
//
// Part 1: 1 to 4 identical 640×360 nodes (stacked-lighting-3.json's projector) on
// many-lights with 20, 50 and 100 lights, the lights split naively (contiguous
// runs of equal length by index). Part 2: the mixed group of
// stacked-lighting-3-auto.json (two 640×360, one 1280×720), naive split against
// the master's cost-model split (automatic_shares), with the model's predicted
// times. All drawn in one run, alternating, over several runs.
//
// In an installation the nodes are separate machines drawing at the same time;
// here they share one GPU (llvmpipe: the CPU) and draw one after another, each
// draw timed on its own, so a node's time is what it would take alone.
//
//   optique-bench-lighting [--config FILE] [--auto-config FILE] [--out DIR] [--frames N] [--repeats R]

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <numeric>
#include <set>
#include <span>
#include <sstream>

#include "bench_options.h"
#include "clock/clock.h"
#include "config/job.h"
#include "config/light_list.h"
#include "config/load.h"
#include "draw_plot.h"
#include "image/compare.h"
#include "image/image_io.h"
#include "master/run/light_share.h"
#include "master/run/scene_authority.h"
#include "master/run/stacked_groups.h"
#include "number_text.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"
#include "scene/builtin.h"
#include "scene/light_coverage.h"
#include "spread.h"

namespace {

using namespace optique;

constexpr std::array<int, 3> kLightCounts{20, 50, 100};
constexpr int kMaxNodes = 4;

// The master's cost model (master/run/stacked_groups.h); main() checks that
// share_lights with it gives what automatic_shares gives.
using master::kAmbientCost;
using master::kBaseCost;

// Seconds of animation between measured frames: the statue turns 0.3 rad/s, so
// the frames see it at different angles.
constexpr double kFrameSpacing = 1.0;

constexpr const char* kReadingHeading = "## What it shows";

struct Node {
  std::unique_ptr<render::ProjectorPipeline> pipeline;
  master::LightShare share;
  [[nodiscard]] const render::SceneRenderer& renderer() const { return pipeline->renderer(); }
};

// One way of drawing a frame: one node drawing everything, or a stacked group
// whose light adds up to it. ms[run][node][frame].
struct Stack {
  std::size_t scene = 0;  // index into kLightCounts
  bool mixed = false;     // the group of the auto config, else `nodes.size()` identical nodes
  std::string split;      // "full", "naive" or "auto"
  std::vector<Node> nodes;
  std::vector<std::vector<std::vector<double>>> ms;
};

// Per frame of the first run, for a stack of identical nodes.
struct Accuracy {
  double split_max_abs = 0.0;  // |Σ rendered − full rendered|, RGB, before quantization
  double exact_psnr = 0.0;     // Σ emitted (8 bits each) against the full render before quantization
  double exact_max_abs = 0.0;
  double one_psnr = 0.0;  // Σ emitted against the full render through one 8-bit projector
  double one_max_abs = 0.0;
  double levels = 0.0;        // distinct green values of Σ emitted along the wall row
  double exact_levels = 0.0;  // … of the full render before quantization
  double brightest = 0.0;     // the full render's largest RGB value (above 1 one projector clips)
  double clipped = 0.0;       // the share of its pixels above 1
};

// Projector `projector` of `installation` drawing `share`, its pipeline built as
// its node builds it, but as an ideal projector (8-bit sRGB, no black: the
// model's default) without blend weights, so that the error measured is the
// split's and the 8-bit steps', not a calibration's.
Node make_node(const scene::SceneDefinition& scene, const config::Installation& installation, std::size_t projector,
               master::LightShare share) {
  config::ProjectorJob job = config::job_for(installation, projector);
  job.installation.projectors[job.projector].response = {};
  auto pipeline = render::ProjectorPipeline::make(job, scene, {.blend = false});
  if (!pipeline) throw std::runtime_error(pipeline.error());
  pipeline.value()->set_share(share);
  return {std::move(pipeline).value(), std::move(share)};
}

// Draws one node's share of a frame; returns the time to a finished image, in ms.
double draw(Node& node, const scene::SceneState& state) {
  const clock::Nanos start = clock::monotonic_now();
  if (auto drawn = node.pipeline->draw(state); !drawn) throw std::runtime_error(drawn.error());
  return static_cast<double>(clock::monotonic_now() - start) / 1e6;
}

// Contiguous runs by index, the first `lights % nodes` one longer: 20 over 3 is
// 0-6, 7-13, 14-19, as stacked-lighting-3.json lists them. Ambient on the first.
std::vector<master::LightShare> naive_split(int lights, int nodes) {
  std::vector<master::LightShare> shares(static_cast<std::size_t>(nodes));
  std::uint32_t next = 0;
  for (int i = 0; i < nodes; ++i) {
    const int count = lights / nodes + (i < lights % nodes ? 1 : 0);
    for (int k = 0; k < count; ++k) shares[static_cast<std::size_t>(i)].lights.push_back(next++);
  }
  shares.front().ambient = true;
  return shares;
}

// The master's state of `scene` at frame k, frames kFrameSpacing apart.
scene::SceneState state_at(const scene::SceneDefinition& scene, const config::Viewer& viewer, int k) {
  return master::SceneAuthority(scene.objects, viewer, 1.0 / kFrameSpacing)
      .state_at_frame(static_cast<std::uint64_t>(k));
}

void add(image::FloatImage& sum, const image::FloatImage& term) {
  for (std::size_t i = 0; i < sum.pixels.size(); ++i) sum.pixels[i] += term.pixels[i];
}

// Over the pixels `where` accepts.
double max_abs_rgb(const image::FloatImage& a, const image::FloatImage& b,
                   const std::function<bool(int x, int y)>& where) {
  double worst = 0.0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (!where(x, y)) continue;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, static_cast<double>(std::abs(a.at(x, y, c) - b.at(x, y, c))));
    }
  }
  return worst;
}

double brightest_rgb(const image::FloatImage& a) {
  double most = 0.0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) most = std::max(most, static_cast<double>(a.at(x, y, c)));
    }
  }
  return most;
}

// Distinct green values along a row, to 1e-6: far finer than an 8-bit step
// (the smallest sRGB step is 1/255/12.92 ≈ 3e-4), coarse enough that equal sums
// added in another order count once.
double distinct_levels(const image::FloatImage& image, int row) {
  std::set<long long> levels;
  for (int x = 0; x < image.width; ++x) levels.insert(std::llround(image.at(x, row, 1) * 1e6));
  return static_cast<double>(levels.size());
}

double median(std::vector<double> v) { return bench::spread(std::move(v)).median; }

// "∞" for identical images, otherwise the spread cell.
std::string cell(const std::vector<double>& values, int decimals) {
  const bench::Spread s = bench::spread(values);
  if (std::isinf(s.low)) return "∞";
  if (std::isinf(s.high)) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*f (%.*f–∞)", decimals, s.median, decimals, s.low);
    return text;
  }
  return bench::cell(s, decimals);
}

using bench::fixed;

std::string scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1e", value);
  return text;
}

// Per run: the median over frames of node i's time, of the slowest node's and of
// the nodes' sum.
struct RunTimes {
  std::vector<std::vector<double>> node;  // [node][run]
  std::vector<double> slowest;            // [run]
  std::vector<double> total;              // [run]
};

RunTimes run_times(const Stack& stack) {
  RunTimes times;
  times.node.resize(stack.nodes.size());
  for (const auto& run : stack.ms) {
    for (std::size_t i = 0; i < run.size(); ++i) times.node[i].push_back(median(run[i]));
    std::vector<double> slowest;
    std::vector<double> total;
    for (std::size_t f = 0; f < run.front().size(); ++f) {
      double most = 0.0;
      double sum = 0.0;
      for (const auto& node : run) {
        most = std::max(most, node[f]);
        sum += node[f];
      }
      slowest.push_back(most);
      total.push_back(sum);
    }
    times.slowest.push_back(median(slowest));
    times.total.push_back(median(total));
  }
  return times;
}

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique lighting-split benchmark: stacked nodes against one full render"};
  std::string config_path = std::string(OPTIQUE_SOURCE_DIR) + "/configs/stacked-lighting-3.json";
  std::string auto_config_path = std::string(OPTIQUE_SOURCE_DIR) + "/configs/stacked-lighting-3-auto.json";
  std::string out = "docs/bench";
  int frames = 5;
  int repeats = 5;
  app.option("--config", config_path, "stacked group whose first projector every identical node copies");
  app.option("--auto-config", auto_config_path, "mixed stacked group with lights \"auto\"");
  app.option("--out", out, "folder for lighting.md, lighting.csv and lighting.png");
  app.option("--frames", frames, "measured frames per run (1 s of animation apart)",
             optique::bench::Bounds::more_than_zero());
  app.option("--repeats", repeats, "runs; times are medians per run, tables their median and min–max",
             optique::bench::Bounds::more_than_zero());
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  try {
    auto loaded = config::load_installation(config_path);
    if (!loaded) throw std::runtime_error(loaded.error());
    const config::Installation& uniform = loaded.value().installation;
    auto loaded_auto = config::load_installation(auto_config_path);
    if (!loaded_auto) throw std::runtime_error(loaded_auto.error());
    const config::Installation& mixed = loaded_auto.value().installation;
    for (const auto* inst : {&uniform, &mixed}) {
      if (inst->viewer.moves()) throw std::runtime_error("the bench needs a fixed viewer eye");
    }
    const std::vector<master::StackedGroup> groups = master::lighting_groups(mixed);
    if (groups.size() != 1 || !groups.front().automatic) {
      throw std::runtime_error(auto_config_path + ": needs exactly one stacked group with lights \"auto\"");
    }
    const master::StackedGroup& group = groups.front();
    const config::Projector& node_projector = uniform.projectors[0];

    std::vector<scene::SceneDefinition> scenes;
    for (int lights : kLightCounts) {
      auto scene =
          scene::builtin_scene(lights == 20 ? std::string("many-lights") : "many-lights-" + std::to_string(lights));
      if (!scene) throw std::runtime_error(scene.error());
      scenes.push_back(std::move(scene).value());
    }

    auto context = render::make_headless_context();
    if (!context) throw std::runtime_error(context.error());
    const std::string gl = context.value()->renderer_name();

    // The stacks, and for the mixed group the cost model's view of both splits.
    std::vector<Stack> stacks;
    std::vector<double> mixed_pixels;
    for (std::size_t member : group.members) {
      const config::Projector& p = mixed.projectors[member];
      mixed_pixels.push_back(static_cast<double>(p.width) * p.height);
    }
    std::vector<std::vector<double>> costs(scenes.size());  // at the first frame's state
    std::vector<int> auto_changes(scenes.size(), 0);        // frames at which automatic_shares would differ
    for (std::size_t s = 0; s < scenes.size(); ++s) {
      const int lights = kLightCounts[s];
      for (int n = 1; n <= kMaxNodes; ++n) {
        Stack stack{s, false, n == 1 ? "full" : "naive", {}, {}};
        for (auto& share : naive_split(lights, n)) {
          stack.nodes.push_back(make_node(scenes[s], uniform, 0, std::move(share)));
        }
        stacks.push_back(std::move(stack));
      }
      const scene::SceneState start = state_at(scenes[s], mixed.viewer, 0);
      const std::vector<bool> live(group.members.size(), true);
      const std::vector<master::LightShare> automatic =
          master::automatic_shares(mixed, group, live, scenes[s], start, start.eye_now);
      costs[s] = master::group_light_costs(mixed, group, scenes[s], start, start.eye_now);
      const std::vector<master::LightShare> copied =
          master::share_lights(costs[s], mixed_pixels, kBaseCost, kAmbientCost);
      for (std::size_t k = 0; k < copied.size(); ++k) {
        if (copied[k].lights != automatic[k].lights || copied[k].ambient != automatic[k].ambient) {
          throw std::runtime_error("the bench's copy of the cost model no longer matches master/run/stacked_groups.cpp");
        }
      }
      for (int k = 1; k < frames; ++k) {
        const scene::SceneState later = state_at(scenes[s], mixed.viewer, k);
        const auto again = master::automatic_shares(mixed, group, live, scenes[s], later, later.eye_now);
        bool differs = false;
        for (std::size_t m = 0; m < again.size(); ++m) differs = differs || again[m].lights != automatic[m].lights;
        auto_changes[s] += differs ? 1 : 0;
      }
      const std::vector<master::LightShare> naive = naive_split(lights, static_cast<int>(group.members.size()));
      for (const auto* split : {&naive, &automatic}) {
        Stack stack{s, true, split == &naive ? "naive" : "auto", {}, {}};
        for (std::size_t k = 0; k < group.members.size(); ++k) {
          stack.nodes.push_back(make_node(scenes[s], mixed, group.members[k], (*split)[k]));
        }
        stacks.push_back(std::move(stack));
      }
    }
    const auto full_of = [&](std::size_t s) -> const Stack& {
      return *std::find_if(stacks.begin(), stacks.end(), [&](const Stack& t) { return t.scene == s && !t.mixed; });
    };

    std::filesystem::create_directories(out);
    std::ofstream csv(out + "/lighting.csv");
    csv << "renderer,group,scene_lights,nodes,split,run,frame,node,metric,value\n";
    const auto csv_row = [&](const Stack& stack, int run, int frame, const std::string& node, const char* metric,
                             double value) {
      csv << '"' << gl << "\"," << (stack.mixed ? "mixed" : "identical") << ',' << kLightCounts[stack.scene] << ','
          << stack.nodes.size() << ',' << stack.split << ',' << run << ',' << frame << ',' << node << ',' << metric
          << ',' << value << '\n';
    };
    // [stack] → per frame of the first run; only stacks of identical nodes.
    std::vector<std::vector<Accuracy>> accuracy(stacks.size());
    const int row = node_projector.height / 10;  // high on the wall, above the statue

    const clock::Nanos bench_start = clock::monotonic_now();
    for (int run = 0; run < repeats; ++run) {
      for (Stack& stack : stacks) {
        stack.ms.emplace_back(stack.nodes.size());
      }
      for (int k = -2; k < frames; ++k) {  // two unmeasured frames first
        for (std::size_t s = 0; s < scenes.size(); ++s) {
          const scene::SceneState state = state_at(scenes[s], uniform.viewer, std::max(k, 0));
          std::vector<std::size_t> order;
          for (std::size_t i = 0; i < stacks.size(); ++i) {
            if (stacks[i].scene == s) order.push_back(i);
          }
          // Rotate which stack goes first, so none always follows another.
          std::rotate(order.begin(), order.begin() + (k + 2 + run) % static_cast<int>(order.size()), order.end());
          for (std::size_t i : order) {
            Stack& stack = stacks[i];
            for (std::size_t n = 0; n < stack.nodes.size(); ++n) {
              const double ms = draw(stack.nodes[n], state);
              if (k < 0) continue;
              stack.ms.back()[n].push_back(ms);
              csv_row(stack, run, k, std::to_string(n), "ms", ms);
            }
          }
          if (run != 0 || k < 0) continue;  // the images do not change between runs
          // Accuracy: each stack's images read back now, while every renderer
          // still holds this frame.
          const Stack& full = full_of(s);
          const image::FloatImage full_rendered = full.nodes.front().renderer().read_rendered();
          const image::FloatImage full_linear = full.nodes.front().renderer().output().read_linear();
          // Where the full render is brighter than one projector can show, one
          // clips and several clip less: a matter of headroom, not of the split
          // or of 8-bit steps, so the comparisons leave those pixels out.
          const auto everywhere = [](int, int) { return true; };
          const auto unclipped = [&](int x, int y) {
            return std::max({full_rendered.at(x, y, 0), full_rendered.at(x, y, 1), full_rendered.at(x, y, 2)}) <= 1.0f;
          };
          double clipped_share = 0.0;
          for (int y = 0; y < full_rendered.height; ++y) {
            for (int x = 0; x < full_rendered.width; ++x) clipped_share += unclipped(x, y) ? 0.0 : 1.0;
          }
          clipped_share /= static_cast<double>(full_rendered.width) * full_rendered.height;
          for (std::size_t i : order) {
            const Stack& stack = stacks[i];
            if (stack.mixed) continue;
            image::FloatImage sum_rendered = stack.nodes.front().renderer().read_rendered();
            image::FloatImage sum_linear = stack.nodes.front().renderer().output().read_linear();
            for (std::size_t n = 1; n < stack.nodes.size(); ++n) {
              add(sum_rendered, stack.nodes[n].renderer().read_rendered());
              add(sum_linear, stack.nodes[n].renderer().output().read_linear());
            }
            Accuracy a;
            a.split_max_abs = max_abs_rgb(sum_rendered, full_rendered, everywhere);
            a.exact_psnr = image::psnr_luma_where(sum_linear, full_rendered, unclipped);
            a.exact_max_abs = max_abs_rgb(sum_linear, full_rendered, unclipped);
            a.one_psnr = image::psnr_luma_where(sum_linear, full_linear, unclipped);
            a.one_max_abs = max_abs_rgb(sum_linear, full_linear, unclipped);
            a.levels = distinct_levels(sum_linear, row);
            a.exact_levels = distinct_levels(full_rendered, row);
            a.brightest = brightest_rgb(full_rendered);
            a.clipped = clipped_share;
            accuracy[i].push_back(a);
            const std::pair<const char*, double> metrics[] = {
                {"split_max_abs", a.split_max_abs},     {"psnr_vs_exact_db", a.exact_psnr},
                {"max_abs_vs_exact", a.exact_max_abs},  {"psnr_vs_one_8bit_db", a.one_psnr},
                {"max_abs_vs_one_8bit", a.one_max_abs}, {"row_levels", a.levels},
                {"row_levels_exact", a.exact_levels},   {"full_brightest", a.brightest},
                {"full_clipped_share", a.clipped}};
            for (const auto& [metric, value] : metrics) csv_row(stack, run, k, "", metric, value);
          }
        }
      }
    }
    const double bench_seconds = static_cast<double>(clock::monotonic_now() - bench_start) / 1e9;

    // The cost model, node time = pixels · (base + Σ light costs [+ ambient]),
    // fitted to every node measured (identical and mixed, all splits): scale and
    // base cost free, least squares of the relative error so that small nodes
    // count as much as large ones. The identical nodes light the same screen area
    // as the mixed group, so their lights cost the same.
    const auto units = [&](std::size_t s, const master::LightShare& share) {
      const std::array<double, 1> one_pixel{1.0};
      return master::modelled_times(costs[s], one_pixel, 0.0, kAmbientCost, std::span(&share, 1)).front();
    };
    double saa = 0.0;
    double sab = 0.0;
    double sbb = 0.0;
    double sa = 0.0;
    double sb = 0.0;
    for (const Stack& stack : stacks) {
      const RunTimes times = run_times(stack);
      for (std::size_t n = 0; n < stack.nodes.size(); ++n) {
        const double t = median(times.node[n]);
        const double pixels = static_cast<double>(stack.nodes[n].renderer().output().width()) *
                              stack.nodes[n].renderer().output().height();
        const double a = pixels / t;
        const double b = pixels * units(stack.scene, stack.nodes[n].share) / t;
        saa += a * a;
        sab += a * b;
        sbb += b * b;
        sa += a;
        sb += b;
      }
    }
    const double det = saa * sbb - sab * sab;
    const double per_base = (sa * sbb - sb * sab) / det;   // ms per pixel
    const double per_light = (saa * sb - sab * sa) / det;  // ms per pixel and unit of light cost
    const double fitted_base = per_base / per_light;
    const auto fitted_ms = [&](std::size_t s, const master::LightShare& share, double pixels) {
      return pixels * (per_base + per_light * units(s, share));
    };

    // Table 1: time. Table 2: accuracy. Both for identical nodes.
    std::ostringstream time_table;
    time_table << "| lights | nodes | lights per node | node ms (median per node) | slowest node ms | speed-up | "
                  "fitted model's speed-up | Σ nodes ms / full ms |\n"
               << "|---:|---:|---|---|---:|---:|---:|---:|\n";
    std::ostringstream accuracy_table;
    accuracy_table << "| lights | nodes | max \\|Σ rendered − full\\| | PSNR Σ 8-bit vs exact, dB | max abs | "
                      "PSNR Σ 8-bit vs one 8-bit, dB | max abs | levels along row " +
                          std::to_string(row) + " (exact)\n"
                   << "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    double brightest = 0.0;
    double clipped = 0.0;
    for (std::size_t i = 0; i < stacks.size(); ++i) {
      const Stack& stack = stacks[i];
      if (stack.mixed) continue;
      const RunTimes times = run_times(stack);
      const RunTimes full = run_times(full_of(stack.scene));
      std::vector<double> speedup;
      std::vector<double> overhead;
      for (std::size_t r = 0; r < times.slowest.size(); ++r) {
        speedup.push_back(full.slowest[r] / times.slowest[r]);
        overhead.push_back(times.total[r] / full.slowest[r]);
      }
      std::string shares;
      std::string node_ms;
      double model_slowest = 0.0;
      for (std::size_t n = 0; n < stack.nodes.size(); ++n) {
        shares += (n ? " / " : "") + std::to_string(stack.nodes[n].share.lights.size());
        node_ms += (n ? " / " : "") + fixed(median(times.node[n]), 1);
        model_slowest = std::max(model_slowest, fitted_ms(stack.scene, stack.nodes[n].share, 1.0));
      }
      const master::LightShare& everything = full_of(stack.scene).nodes.front().share;
      const double model_speedup = fitted_ms(stack.scene, everything, 1.0) / model_slowest;
      const std::size_t n = stack.nodes.size();
      time_table << "| " << kLightCounts[stack.scene] << " | " << n << " | " << shares << " | " << node_ms << " | "
                 << cell(times.slowest, 1) << " | " << cell(speedup, 2) << " | " << fixed(model_speedup, 2) << " | "
                 << cell(overhead, 2) << " |\n";

      std::vector<double> split, exact_psnr, exact_max, one_psnr, one_max, levels, exact_levels;
      for (const Accuracy& a : accuracy[i]) {
        split.push_back(a.split_max_abs);
        exact_psnr.push_back(a.exact_psnr);
        exact_max.push_back(a.exact_max_abs);
        one_psnr.push_back(a.one_psnr);
        one_max.push_back(a.one_max_abs);
        levels.push_back(a.levels);
        exact_levels.push_back(a.exact_levels);
        brightest = std::max(brightest, a.brightest);
        clipped = std::max(clipped, a.clipped);
      }
      accuracy_table << "| " << kLightCounts[stack.scene] << " | " << n << " | " << scientific(median(split)) << " ("
                     << scientific(*std::max_element(split.begin(), split.end())) << ") | " << cell(exact_psnr, 1)
                     << " | " << cell(exact_max, 4) << " | " << cell(one_psnr, 1) << " | " << cell(one_max, 4) << " | "
                     << cell(levels, 0) << " (" << fixed(median(exact_levels), 0) << ") |\n";
    }

    // Table 3: the mixed group. The master's model (base cost kBaseCost) turns
    // into ms by one factor for all rows, least squares through the origin.
    struct MixedRow {
      const Stack* stack;
      std::vector<double> modelled;
      RunTimes times;
    };
    std::vector<MixedRow> mixed_rows;
    double fit_num = 0.0;
    double fit_den = 0.0;
    for (const Stack& stack : stacks) {
      if (!stack.mixed) continue;
      std::vector<master::LightShare> shares;
      for (const Node& node : stack.nodes) shares.push_back(node.share);
      MixedRow r{&stack, master::modelled_times(costs[stack.scene], mixed_pixels, kBaseCost, kAmbientCost, shares),
                 run_times(stack)};
      for (std::size_t n = 0; n < stack.nodes.size(); ++n) {
        fit_num += r.modelled[n] * median(r.times.node[n]);
        fit_den += r.modelled[n] * r.modelled[n];
      }
      mixed_rows.push_back(std::move(r));
    }
    const double ms_per_unit = fit_num / fit_den;
    std::ostringstream mixed_table;
    mixed_table << "| lights | split | node | pixels | lights drawn | ambient | measured ms | master's model, ms | "
                   "fitted model, ms |\n"
                << "|---:|---|---|---:|---|---|---:|---:|---:|\n";
    std::ostringstream mixed_summary;
    mixed_summary << "| lights | split | lights per node | slowest node ms, measured | master's model | fitted model "
                     "| naive / auto, measured | master's model |\n"
                  << "|---:|---|---|---:|---:|---:|---:|---:|\n";
    for (std::size_t i = 0; i < mixed_rows.size(); ++i) {
      const MixedRow& r = mixed_rows[i];
      const Stack& stack = *r.stack;
      std::string counts;
      double fitted_slowest = 0.0;
      for (std::size_t n = 0; n < stack.nodes.size(); ++n) {
        const config::Projector& p = mixed.projectors[group.members[n]];
        const double fitted = fitted_ms(stack.scene, stack.nodes[n].share, mixed_pixels[n]);
        fitted_slowest = std::max(fitted_slowest, fitted);
        counts += (n ? " / " : "") + std::to_string(stack.nodes[n].share.lights.size());
        mixed_table << "| " << kLightCounts[stack.scene] << " | " << stack.split << " | " << p.id << " | " << p.width
                    << "×" << p.height << " | " << config::format_light_list(stack.nodes[n].share.lights) << " ("
                    << stack.nodes[n].share.lights.size() << ") | " << (stack.nodes[n].share.ambient ? "yes" : "")
                    << " | " << cell(r.times.node[n], 1) << " | " << fixed(ms_per_unit * r.modelled[n], 1) << " | "
                    << fixed(fitted, 1) << " |\n";
      }
      const double modelled_slowest = *std::max_element(r.modelled.begin(), r.modelled.end());
      mixed_summary << "| " << kLightCounts[stack.scene] << " | " << stack.split << " | " << counts << " | "
                    << cell(r.times.slowest, 1) << " | " << fixed(ms_per_unit * modelled_slowest, 1) << " | "
                    << fixed(fitted_slowest, 1) << " | ";
      if (stack.split == "auto") {
        const MixedRow& naive = mixed_rows[i - 1];  // built just before it
        std::vector<double> gain;
        for (std::size_t run = 0; run < r.times.slowest.size(); ++run) {
          gain.push_back(naive.times.slowest[run] / r.times.slowest[run]);
        }
        const double naive_model = *std::max_element(naive.modelled.begin(), naive.modelled.end());
        mixed_summary << cell(gain, 2) << " | " << fixed(naive_model / modelled_slowest, 2) << " |\n";
        // What share_lights would choose with the fitted base cost: predicted
        // only, not drawn.
        const std::vector<master::LightShare> refit =
            master::share_lights(costs[stack.scene], mixed_pixels, fitted_base, kAmbientCost);
        std::string refit_counts;
        double refit_slowest = 0.0;
        for (std::size_t n = 0; n < refit.size(); ++n) {
          refit_counts += (n ? " / " : "") + std::to_string(refit[n].lights.size());
          refit_slowest = std::max(refit_slowest, fitted_ms(stack.scene, refit[n], mixed_pixels[n]));
        }
        mixed_summary << "| " << kLightCounts[stack.scene] << " | auto, fitted base (not drawn) | " << refit_counts
                      << " | | | " << fixed(refit_slowest, 1) << " | | |\n";
      } else {
        mixed_summary << " | |\n";
      }
    }

    // The reading below the tables is written by hand from a run's numbers; a
    // re-run keeps it (and should be read again against the new tables).
    std::string reading;
    if (std::ifstream previous(out + "/lighting.md"); previous) {
      std::stringstream text;
      text << previous.rdbuf();
      const std::string old = text.str();
      if (const auto at = old.find(kReadingHeading); at != std::string::npos) reading = old.substr(at);
    }
    std::string cost_summary;
    for (std::size_t s = 0; s < scenes.size(); ++s) {
      std::vector<double> c = costs[s];
      std::sort(c.begin(), c.end());
      cost_summary += (s ? "; " : "") + std::to_string(kLightCounts[s]) + " lights " + fixed(c.front(), 2) + " / " +
                      fixed(median(c), 2) + " / " + fixed(c.back(), 2);
    }
    std::ostringstream md;
    md << "# Lighting split: stacked nodes against one full render\n\n"
       << "Majumder & Welch's lighting split ([docs/design.md](../design.md), \"The lighting split\"): each node of a "
          "stacked group draws "
          "some of the scene's point lights, one of them also the ambient and emissive terms, and the projectors' "
          "light adds up on the screen to the full render. What the cluster buys is the frame time of its slowest "
          "node against one node drawing every light; what it costs is the error of the optical sum.\n\n"
       << "```\nbuild/bin/optique-bench-lighting --out docs/bench   # --frames " << frames << " --repeats " << repeats
       << " by default\n```\n\n"
       << "## How it is measured\n\n"
       << "- Renderer: " << gl << ". " << frames << " frames (" << kFrameSpacing
       << " s of animation apart: the statue turns) × " << repeats << " runs, after two unmeasured frames per run; "
       << fixed(bench_seconds, 0)
       << " s in all. In each frame every stack below draws the same scene state, the "
          "order of the stacks rotating from frame to frame.\n"
       << "- The nodes of an installation are separate machines drawing at the same time. Here they share one GPU "
          "(llvmpipe: the CPU's cores) and draw one after another in one process, each draw timed on its own (to a "
          "finished image, glFinish), so a node's time is what it would take alone. The cluster's frame time is the "
          "slowest node's; speed-up = full render's time / slowest node's, per run. Σ nodes / full is the work the "
          "split adds in all (each node rasterizes the whole scene and runs the output pass).\n"
       << "- Times: median over frames per run, then median (min–max) over runs; per-node columns are medians.\n"
       << "- Identical nodes: " << node_projector.width << "×" << node_projector.height << ", projector '"
       << node_projector.id << "' of " << config_path.substr(config_path.rfind('/') + 1)
       << " (same screen and eye), 1 to " << kMaxNodes
       << " of them; 1 is the full render. Naive split: contiguous runs of equal length by index (the first "
          "lights % nodes one longer), ambient and emissive on the first node.\n"
       << "- Projectors: all ideal and alike, 8-bit sRGB, no black level (ProjectorModel's default), so the error "
          "is the split's and the 8-bit steps', not a calibration's. Accuracy from the frames of the first run "
          "(images do not change between runs), median (min–max) over frames:\n"
       << "  - max |Σ rendered − full|: the nodes' linear light before the output pass (read_rendered) summed, against "
          "the "
          "full render's, largest RGB difference (median, then the worst frame in brackets).\n"
       << "  - Σ 8-bit vs exact: the light the projectors emit after 8-bit quantization, summed, against the full "
          "render before quantization; PSNR of luma, peak 1, and the largest RGB difference. For 1 node this is one "
          "projector's quantization error. The emitted light is read back from the renderer's RGBA16F output "
          "(read_linear): its rounding, at most 2^-11 of the value, is a small fraction of an 8-bit step.\n"
          "  - Only over the pixels where the full render is at most 1 in every channel: elsewhere one projector "
          "clips and several clip less, which is headroom (more light), not accuracy. The full render's brightest "
          "value is "
       << fixed(brightest, 2) << ", and at most " << fixed(100.0 * clipped, 2) << " % of its pixels are above 1.\n"
       << "  - Σ 8-bit vs one 8-bit: the same sum against the full render through one 8-bit projector.\n"
       << "  - levels along row " << row
       << " (high on the wall, above the statue): distinct green values of the summed emitted light across the row; "
          "in brackets the full render's before quantization (what the scene asks for).\n"
       << "- Mixed group: the three projectors of " << auto_config_path.substr(auto_config_path.rfind('/') + 1)
       << " with the naive split against automatic_shares (the master's cost-model split, computed at the first "
          "frame's state, as the master does before it rebalances). Modelled times: modelled_times under the same "
          "costs (base cost "
       << kBaseCost
       << " light), turned into ms by one factor for all rows of the table "
          "(least squares through the origin: "
       << scientific(ms_per_unit)
       << " ms per pixel and unit of cost), so the model is judged on its ratios. Fitted model: the same form, "
          "node ms = pixels · (a + b · Σ light costs), a and b fitted to every node drawn (identical and mixed, "
          "relative least squares): a = "
       << scientific(per_base) << " ms, b = " << scientific(per_light) << " ms per pixel, a base cost of "
       << fixed(fitted_base, 1) << " lights instead of " << kBaseCost << ". Light costs (coverage of the screen, "
       << "min / median / max): " << cost_summary
       << ". "
          "Frames at which automatic_shares alone (without the master's hysteresis: it shares out again only for a "
          "worthwhile modelled gain) would split differently from its first split (20/50/100 lights): "
       << auto_changes[0] << "/" << auto_changes[1] << "/" << auto_changes[2] << " of " << frames - 1 << ".\n"
       << "- Plot (`lighting.png`): the speed-up per light count with the ideal (= nodes), and the PSNR of Σ 8-bit vs "
          "exact, against the node count; the fitted model's speed-up is in the table.\n\n"
       << "## Identical nodes, naive split\n\n"
       << time_table.str() << "\n"
       << accuracy_table.str() << "\n"
       << "## Mixed group: naive vs auto\n\n"
       << mixed_table.str() << "\n"
       << mixed_summary.str() << "\n";
    if (!reading.empty()) md << reading;
    std::ofstream(out + "/lighting.md") << md.str();
    std::cout << md.str();
    csv.close();
    if (!bench::draw_plot(out, "lighting")) return 1;
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-lighting: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
