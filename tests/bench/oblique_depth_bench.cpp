// Oblique depth benchmark: visibility errors of the single-pass oblique
// projection against exact per-pixel visibility, as the projector's incidence
// grows, for layer separations δ from 1 cm to 0.01 mm, with 24-bit fixed and
// 32-bit float depth; beside it, eq. 5 of the paper and the viewer's own
// aligned frustum (the depth buffer's own limit). Writes oblique-depth.md,
// oblique-depth.csv, oblique-depth.png (the plot) and oblique-depth-maps.png
// (error maps) to --out.
//
//   optique-bench-oblique-depth [--out DIR]

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench_options.h"
#include "draw_plot.h"
#include "image/image_io.h"
#include "number_text.h"
#include "oblique_depth_experiment.h"
#include "render/gl_context.h"
#include "util/join.h"

namespace {

using namespace optique;
using namespace optique::bench::oblique_depth;
using render::DepthFormat;

struct Series {
  std::string name;
  std::string what;
  double azimuth_deg;
  double distance;
  double roll_deg;
  std::vector<double> incidences;
};

// Three installations: a plain sideways projector; one diagonal and rolled,
// close to the wall, whose lit quad runs off the wall; one closer still and
// more askew, whose R has unlit corners near the projector's horizon (where
// eq. 5's factor reaches zero before the image itself reaches the horizon, at
// 42°, so its incidences stop there).
const std::vector<Series> kSeries{
    {"yaw",
     "sideways (yaw about the wall's vertical), 1.5 m from the wall's centre",
     0.0,
     1.5,
     0.0,
     {0, 30, 45, 60, 70, 75, 80, 85}},
    {"diagonal-rolled",
     "from the upper right (azimuth 45°), image rolled 30°, 0.9 m from the wall's centre",
     45.0,
     0.9,
     30.0,
     {0, 30, 45, 60, 70, 75, 80, 85}},
    {"askew-close",
     "from the upper right (azimuth 45°), image rolled 45°, 0.5 m from the wall's centre",
     45.0,
     0.5,
     45.0,
     {0, 20, 30, 34, 36, 37, 38, 40}},
};
const std::vector<double> kDeltas{1e-2, 1e-3, 1e-4, 3e-5, 1e-5};

struct Run {
  Method method;
  DepthFormat format;
  const char* name;
};
const std::array<Run, 7> kRuns{{{Method::ours, DepthFormat::fixed24, "ours,fixed24"},
                                {Method::ours, DepthFormat::float32, "ours,float32"},
                                {Method::paper, DepthFormat::fixed24, "paper,fixed24"},
                                {Method::paper, DepthFormat::float32, "paper,float32"},
                                {Method::aligned, DepthFormat::fixed24, "aligned,fixed24"},
                                {Method::aligned, DepthFormat::float32, "aligned,float32"},
                                {Method::naive, DepthFormat::float32, "naive,float32"}}};
enum RunIndex { kOurs24, kOurs32, kPaper24, kPaper32, kAligned24, kAligned32, kNaive32 };

// Error maps worth looking at: (series, θ, δ, run).
struct Tile {
  std::string series;
  double incidence;
  double delta;
  int run;
  std::string caption;
};
const std::vector<Tile> kTiles{
    {"diagonal-rolled", 70, 3e-5, kOurs24, "ours, diagonal-rolled 70°, δ 0.03 mm, 24-bit"},
    {"diagonal-rolled", 70, 3e-5, kAligned24, "aligned, same frame and δ, 24-bit"},
    {"askew-close", 36, 1e-4, kPaper24, "paper eq. 5, askew-close 36°, δ 0.1 mm, 24-bit"},
    {"askew-close", 36, 1e-4, kOurs24, "ours, same frame and δ, 24-bit"},
};

using bench::fixed;

std::string delta_text(double delta) {
  if (delta >= 1e-2) return "1 cm";
  if (delta >= 1e-3) return "1 mm";
  if (delta >= 1e-4) return "0.1 mm";
  if (delta >= 3e-5) return "0.03 mm";
  return "0.01 mm";
}

// A tile of an error map: the exact answer dimmed, excluded pixels grey, masked
// (off the wall) pixels dark, errors white.
void paint(image::ByteImage& map, int x0, int y0, const Experiment& experiment, int width, int height) {
  static const unsigned char kDim[kObjectCount][3] = {
      {0, 0, 0}, {110, 20, 20}, {20, 100, 20}, {20, 20, 120}, {100, 100, 20}};
  const auto& verdicts = experiment.last_verdicts();
  const auto& truth = experiment.last_truth();
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const auto at = static_cast<std::size_t>(y) * width + x;
      const unsigned char* c = kDim[truth[at]];
      std::array<unsigned char, 3> rgb{c[0], c[1], c[2]};
      if (verdicts[at] == 1) rgb = {70, 70, 70};
      if (verdicts[at] == 2) rgb = {255, 255, 255};
      if (verdicts[at] == 3)
        rgb = {static_cast<unsigned char>(c[0] / 4), static_cast<unsigned char>(c[1] / 4),
               static_cast<unsigned char>(c[2] / 4)};
      for (int ch = 0; ch < 3; ++ch) map.at(x0 + x, y0 + y, ch) = rgb[static_cast<std::size_t>(ch)];
      map.at(x0 + x, y0 + y, 3) = 255;
    }
  }
}

// Error rate of front-layer pixels by their exact window-z gap.
struct GapBins {
  static constexpr std::array<double, 10> kEdges{0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 8.0, 1e300};
  std::array<long, 9> pixels{};
  std::array<long, 9> errors{};
  double largest_error_gap = 0.0;
  void add(const Experiment& e) {
    const auto& gaps = e.last_gaps();
    const auto& verdicts = e.last_verdicts();
    for (std::size_t i = 0; i < gaps.size(); ++i) {
      if (std::isnan(gaps[i])) continue;
      for (std::size_t b = 0; b + 1 < kEdges.size(); ++b) {
        if (gaps[i] >= kEdges[b] && gaps[i] < kEdges[b + 1]) {
          ++pixels[b];
          if (verdicts[i] == 2) {
            ++errors[b];
            largest_error_gap = std::max(largest_error_gap, static_cast<double>(gaps[i]));
          }
        }
      }
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique oblique depth benchmark"};
  std::string out = "docs/bench";
  app.option("--out", out, "folder for oblique-depth.md, .csv, .png (plot) and -maps.png");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  auto context = render::make_headless_context();
  if (!context) {
    std::cerr << "optique-bench-oblique-depth: " << context.error() << "\n";
    return 1;
  }
  const std::string gl = context.value()->renderer_name();
  Experiment experiment(installation());
  const Installation& inst = experiment.installation();

  std::filesystem::create_directories(out);
  std::ofstream csv(out + "/oblique-depth.csv");
  csv << "renderer,series,azimuth_deg,roll_deg,distance_m,incidence_deg,throw_ratio,k_ours,factor_paper,"
         "compression_ours,compression_paper,delta_m,method,depth,counted,excluded,masked,errors,front_pixels,"
         "min_gap_steps,under_two_steps\n";
  std::ostringstream tables;
  std::map<std::string, GapBins> bins;  // by depth format, single pass (ours and paper) and aligned
  image::ByteImage map(2 * 640, 2 * 400, 4);
  std::vector<std::string> captions(kTiles.size());
  int differing_formats = 0;
  int differing_outside_negative_paper = 0;  // pairs that differ other than eq. 5 with a factor ≤ 0
  int compared_formats = 0;
  // By δ: frames with any error, per method (either format), and frames in all.
  std::map<double, std::array<int, 3>> frames_with_errors;
  std::map<double, int> frames;
  std::map<double, double> min_ours_gap;  // by δ, over frames (24-bit run)
  double min_k = 1e300;
  double min_compression_ours = 1e300;
  std::vector<std::string> paper_nonpositive;
  bool naive_always_fails = true;

  for (const Series& s : kSeries) {
    tables << "\n### " << s.name << ": " << s.what << "\n\n"
           << "| θ | throw | k ours | 1−\\|a31\\|−\\|a32\\| | c ours / paper | δ | pixels (excluded, masked) | ours "
              "24 / 32F | paper 24 / 32F | aligned 24 / 32F | naive 32F | min gap ours / paper / aligned |\n"
           << "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (double incidence : s.incidences) {
      Placement placement;
      placement.series = s.name;
      placement.incidence_deg = incidence;
      placement.azimuth_deg = s.azimuth_deg;
      placement.distance = s.distance;
      placement.roll_deg = s.roll_deg;
      auto projector = make_projector(inst, placement);
      if (!projector) {
        tables << "| " << incidence << "° | | | | | | " << projector.error() << " | | | | | |\n";
        continue;
      }
      const Projector& p = projector.value();
      min_k = std::min(min_k, p.k);
      min_compression_ours = std::min(min_compression_ours, p.ours_compression);
      if (p.paper_factor <= 0.0) {
        paper_nonpositive.push_back(s.name + " " + fixed(incidence, 0) + "° (" + fixed(p.paper_factor, 3) + ")");
      }
      bool first = true;
      for (double delta : kDeltas) {
        std::array<Count, kRuns.size()> c;
        for (std::size_t r = 0; r < kRuns.size(); ++r) {
          auto count = experiment.measure(p, delta, kRuns[r].method, kRuns[r].format);
          if (!count) {
            std::cerr << "optique-bench-oblique-depth: " << count.error() << "\n";
            return 1;
          }
          c[r] = count.value();
          const bool fixed24 = kRuns[r].format == DepthFormat::fixed24;
          if (kRuns[r].method == Method::ours || kRuns[r].method == Method::paper) {
            bins[fixed24 ? "single pass, 24-bit" : "single pass, 32F"].add(experiment);
          } else if (kRuns[r].method == Method::aligned) {
            bins[fixed24 ? "aligned, 24-bit" : "aligned, 32F"].add(experiment);
          }
          for (std::size_t t = 0; t < kTiles.size(); ++t) {
            const Tile& tile = kTiles[t];
            if (tile.series == s.name && tile.incidence == incidence && tile.delta == delta &&
                tile.run == static_cast<int>(r)) {
              paint(map, static_cast<int>(t % 2) * 640, static_cast<int>(t / 2) * 400, experiment, 640, 400);
              captions[t] = tile.caption + ": " + std::to_string(c[r].errors) + " errors";
            }
          }
          csv << '"' << gl << "\"," << s.name << ',' << s.azimuth_deg << ',' << s.roll_deg << ',' << s.distance << ','
              << incidence << ',' << p.throw_ratio << ',' << p.k << ',' << p.paper_factor << ',' << p.ours_compression
              << ',' << p.paper_compression << ',' << delta << ',' << kRuns[r].name << ',' << c[r].counted << ','
              << c[r].excluded << ',' << c[r].masked << ',' << c[r].errors << ',' << c[r].front_pixels << ','
              << c[r].min_gap_steps << ',' << c[r].under_two_steps << '\n';
        }
        for (auto [a, b] : {std::pair{kOurs24, kOurs32}, {kPaper24, kPaper32}, {kAligned24, kAligned32}}) {
          ++compared_formats;
          if (c[a].errors != c[b].errors) {
            ++differing_formats;
            if (!(a == kPaper24 && p.paper_factor <= 0.0)) ++differing_outside_negative_paper;
          }
        }
        ++frames[delta];
        min_ours_gap.try_emplace(delta, 1e300);
        min_ours_gap[delta] = std::min(min_ours_gap[delta], c[kOurs24].min_gap_steps);
        auto& with_errors = frames_with_errors[delta];
        if (c[kOurs24].errors + c[kOurs32].errors > 0) ++with_errors[0];
        if (c[kPaper24].errors + c[kPaper32].errors > 0) ++with_errors[1];
        if (c[kAligned24].errors + c[kAligned32].errors > 0) ++with_errors[2];
        if (incidence > 0.0 && c[kNaive32].errors < c[kNaive32].counted / 4) naive_always_fails = false;
        tables << "| " << (first ? fixed(incidence, 0) + "°" : "") << " | " << (first ? fixed(p.throw_ratio, 2) : "")
               << " | " << (first ? fixed(p.k, 3) : "") << " | " << (first ? fixed(p.paper_factor, 3) : "") << " | "
               << (first ? fixed(p.ours_compression, 3) + " / " + fixed(p.paper_compression, 3) : "") << " | "
               << delta_text(delta) << " | " << c[kOurs24].counted << " (" << c[kOurs24].excluded << ", "
               << c[kOurs24].masked << ") | " << c[kOurs24].errors << " / " << c[kOurs32].errors << " | "
               << c[kPaper24].errors << " / " << c[kPaper32].errors << " | " << c[kAligned24].errors << " / "
               << c[kAligned32].errors << " | " << c[kNaive32].errors << " | " << fixed(c[kOurs24].min_gap_steps, 2)
               << " / " << fixed(c[kPaper24].min_gap_steps, 2) << " / " << fixed(c[kAligned24].min_gap_steps, 2)
               << " |\n";
        first = false;
        std::cout << s.name << " θ=" << incidence << " δ=" << delta << " k=" << p.k << " f=" << p.paper_factor
                  << " ours " << c[kOurs24].errors << "/" << c[kOurs32].errors << " paper " << c[kPaper24].errors << "/"
                  << c[kPaper32].errors << " aligned " << c[kAligned24].errors << "/" << c[kAligned32].errors
                  << " naive " << c[kNaive32].errors << std::endl;
      }
    }
  }

  // Where popping starts: the smallest δ above which a method never erred.
  auto clean_from = [&](int method) {
    double clean = 0.0;
    for (auto it = frames_with_errors.rbegin(); it != frames_with_errors.rend(); ++it) {
      if (it->second[static_cast<std::size_t>(method)] > 0) break;
      clean = it->first;
    }
    return clean;
  };
  std::ostringstream summary;
  summary << "| δ | frames | ours: frames with errors | paper eq. 5 | aligned |\n|---:|---:|---:|---:|---:|\n";
  for (auto it = frames_with_errors.rbegin(); it != frames_with_errors.rend(); ++it) {
    summary << "| " << delta_text(it->first) << " | " << frames[it->first] << " | " << it->second[0] << " | "
            << it->second[1] << " | " << it->second[2] << " |\n";
  }
  // "no error at δ ≥ 0.1 mm in any of 24 frames; at 0.03 mm 18 of 24 frames pop, at 0.01 mm 24".
  auto describe = [&](int method) {
    const auto m = static_cast<std::size_t>(method);
    std::string text;
    if (const double clean = clean_from(method); clean > 0.0) {
      text = "no error at δ ≥ " + delta_text(clean) + " in any of " + std::to_string(frames[clean]) + " frames";
    }
    int shown = 0;
    for (auto it = frames_with_errors.rbegin(); it != frames_with_errors.rend(); ++it) {
      if (it->second[m] <= shown) continue;
      text += (text.empty() ? "at "
               : shown == 0 ? "; at "
                            : ", at ") +
              delta_text(it->first) + " " + std::to_string(it->second[m]) +
              (shown == 0 ? " of " + std::to_string(frames[it->first]) + " frames pop" : "");
      shown = it->second[m];
    }
    return text;
  };
  double largest_error_gap = 0.0;
  for (const auto& [name, b] : bins) largest_error_gap = std::max(largest_error_gap, b.largest_error_gap);
  constexpr double kFarthest = 5.0;  // eye depth of the layers' far end (m)
  const double resolvable_mm =
      1e3 * largest_error_gap / 16777216.0 * kFarthest * kFarthest * (inst.far - inst.near) / (inst.near * inst.far);

  std::ostringstream gaps;
  gaps << "| exact gap (steps of 2⁻²⁴) |";
  for (const auto& [name, b] : bins) gaps << ' ' << name << " |";
  gaps << "\n|---|";
  for (std::size_t i = 0; i < bins.size(); ++i) gaps << "---:|";
  gaps << '\n';
  for (std::size_t i = 0; i + 1 < GapBins::kEdges.size(); ++i) {
    gaps << "| " << fixed(GapBins::kEdges[i], 1) << " – "
         << (GapBins::kEdges[i + 1] > 1e100 ? std::string("∞") : fixed(GapBins::kEdges[i + 1], 1)) << " |";
    for (const auto& [name, b] : bins) {
      gaps << ' '
           << (b.pixels[i] == 0
                   ? std::string("–")
                   : fixed(100.0 * static_cast<double>(b.errors[i]) / static_cast<double>(b.pixels[i]), 2) + "% of " +
                         std::to_string(b.pixels[i]))
           << " |";
    }
    gaps << '\n';
  }

  if (auto written = image::write_png(out + "/oblique-depth-maps.png", map); !written) {
    std::cerr << "optique-bench-oblique-depth: " << written.error() << "\n";
    return 1;
  }

  std::ofstream md(out + "/oblique-depth.md");
  md << "# Oblique projection: depth order, measured\n\n"
     << "Generated by `optique-bench-oblique-depth` on " << gl
     << ". [docs/design.md](../design.md) (Raskar's oblique projector, **Depth**) "
     << "argues that a 4×4 projective map keeps per-pixel depth order and that the third-row factor k only "
        "compresses depth. This counts visibility errors of single-pass rendering against exact per-pixel "
        "visibility.\n\n"
     << "**Setup.** A 2 m × 1.2 m wall in the world plane z = 0 (lower-left corner at (−1, 0.9, 0)), the eye 2 m in "
        "front of its centre, near/far "
     << inst.near << " / " << inst.far
     << " m. A pinhole projector of 640×400 square pixels aimed at the wall's centre at incidence θ; its throw "
        "ratio is chosen so that the image's middle row spans 1.6 m of wall, so only the obliqueness changes. "
        "H = K·[r1 r2 t] (screen metres → pixels) goes through `ProjectorGeometry::make` and `ProjectorView::make` "
        "(single pass) unchanged. The scene (no lights, ambient 0, one emissive colour per object, so the colour is "
        "the object's id): a back and a front quad, parallel and δ apart, tilted so that they run from 1 m to 3 m "
        "behind the wall (the back one drawn first, so a depth tie shows the wrong one), and two quads crossing at a "
        "shallow angle about 2 m behind the wall. Exact visibility: each pixel centre p goes to the wall by H⁻¹, the "
        "eye's ray through that point meets the quads (the renderer's own float vertices) in double precision.\n\n"
     << "**Counting.** Pixels whose exact answer changes within one pixel of their centre (3×3 neighbourhood: "
        "silhouettes, the intersection line) are excluded, and pixels off the wall (outside R, masked in a real "
        "installation) are not counted; the tables give both. An error is a counted pixel showing another object "
        "(nearest emissive colour) than the exact answer.\n\n"
     << "**Methods.** *ours*: `ProjectorView::frustum` (A′·P_U, third row k = w_min/w_max over the lit quad within the "
        "wall). "
        "*paper*: the same A normalized to a33 = 1 with eq. 5's third row 1 − |a31| − |a32|. *aligned*: the viewer's "
        "own off-axis frustum through the same R at 640×400, no A: what the depth buffer resolves at that δ anyway. "
        "*naive*: A with the third row [0 0 1 0], a deliberately wrong depth row (z/w leaves [−1, 1] where w < 1, "
        "so it clips), to show that the counter catches what it should. *c*: the smallest depth_scale / w over the "
        "pixels inside R, i.e. how much the viewer frustum's depth differences shrink at the worst pixel (per pixel "
        "it is w_min/w, with w_min over the lit quad within the wall for ours and over R's corners for the paper). "
        "*min gap*: the "
        "smallest exact window-z difference between the front and back layer over the front layer's counted pixels, "
        "in steps of 2⁻²⁴ (one step of a 24-bit buffer): the theory column, "
        "gap ≈ c · n·f/(f−n) · Δz_e / z_e² · 2²⁴ for an eye-depth separation Δz_e at eye depth z_e.\n\n"
     << "## Summary\n\nFrames (series × θ) in which a method showed any visibility error, either depth format.\n\n"
     << summary.str() << "\n## Results\n"
     << tables.str() << "\n## Error rate by exact gap\n\n"
     << "Front-layer pixels of every frame above, by their exact window-z gap; the share shown wrong.\n\n"
     << gaps.str() << "\n## Error maps\n\n"
     << "`oblique-depth-maps.png`, 2×2 tiles of projector pixels: the exact answer dimmed (red back, green front, blue "
        "and yellow the crossing pair), grey excluded, dark masked, white errors. Top left: "
     << captions[0] << "; top right: " << captions[1] << "; bottom left: " << captions[2]
     << "; bottom right: " << captions[3] << ".\n\n![error maps](oblique-depth-maps.png)\n\n"
     << "## Plot\n\n![the depth compression c of ours and of eq. 5 against θ per series; the worst share of wrong "
        "pixels against δ per method](oblique-depth.png)\n\n"
     << "## Findings\n\n"
     << "- **Where popping starts.** Ours (θ up to 85°, c down to " << fixed(min_compression_ours, 3)
     << ", either depth format): " << describe(0) << ". Aligned: " << describe(2) << ". Eq. 5: " << describe(1) << ".\n"
     << "- **Cause: δ against depth precision, scaled by c; not obliqueness as such.** Every wrong pixel (naive row "
        "aside) had an exact window-z gap below "
     << fixed(largest_error_gap, 2)
     << " steps of 2⁻²⁴, and the error rate falls with the exact gap alike for the single pass and the aligned "
        "frustum (table above). Obliqueness only shrinks the gap, by c; depth order itself holds: at 1 mm and 1 cm "
        "nothing pops at any θ, and the crossing pair's intersection line lands where exact visibility puts it, to "
        "within the excluded one-pixel band (window z is affine per triangle under a 4×4 projective map, as the "
        "design argues).\n"
     << "- **24-bit vs 32F.** " << differing_formats << " of " << compared_formats
     << " (method, frame) pairs differ in their error count"
     << (differing_formats > 0 && differing_outside_negative_paper == 0 ? ", all of them eq. 5 frames with a factor ≤ 0"
                                                                        : "")
     << ". The standard mapping puts everything beyond about 2·near at window z ∈ [0.5, 1), where a float has the "
        "same 2⁻²⁴ spacing as 24-bit fixed point, and the clip-space arithmetic before it is float32 anyway; only a "
        "negative factor pushes window z below 0.5, where float32 is finer. 32F should pay off only with a [0, 1] "
        "clip range and reversed depth (glClipControl), which the renderer does not use (not measured here).\n"
     << "- **Theory.** A separation Δz_e at eye depth z_e is c·n·f/((f−n)·z_e²)·Δz_e in window z (the gap "
        "columns), so the smallest resolvable separation is about s·2⁻²⁴·z_e²/(n·c), with s ≈ "
     << fixed(largest_error_gap, 1) << " steps as measured: " << fixed(resolvable_mm, 3)
     << " mm / c at z_e = 5 m (the farthest layer) with near = " << inst.near
     << " m (in eye depth the tilted layers are a little more than δ apart). Aligned (c = 1) that is right at the "
        "0.03 mm row; for ours (c ≥ "
     << fixed(min_compression_ours, 2) << ") it is " << fixed(resolvable_mm / min_compression_ours, 2)
     << " mm at worst, where the most compressed pixel also sees the farthest layer. In these frames the two do "
        "not meet: ours' smallest exact gap at 0.1 mm is "
     << fixed(min_ours_gap[1e-4], 2)
     << " steps, and the counts follow the exact per-pixel gap. A larger near plane buys precision linearly.\n"
     << "- **Eq. 5 vs ours.** Eq. 5 bounds w over R's corners, ours over the lit quad within the wall. Where the two "
        "bounds "
        "coincide (yaw; diagonal-rolled from 70°) both give the same window z, and their different counts at "
        "0.03 mm are float rounding at 1–2 steps of gap. In askew setups R's unlit corner nears the projector's "
        "horizon before the image does: eq. 5's c collapses (askew-close: it pops at 0.1 mm where ours is exact) "
        "and its factor reaches ≤ 0 at "
     << (paper_nonpositive.empty() ? std::string("no frame") : util::joined(paper_nonpositive))
     << ", where depth is reversed and nearly every front pixel is wrong even 1 cm apart; ours keeps k > 0 "
        "(smallest "
     << fixed(min_k, 4) << ").\n"
     << "- **k is the precision figure once it is bounded over what is shown.** With the bound over the whole lit "
        "quad (the first version), k fell to a few hundredths in diagonal-rolled while c stayed near a quarter: the "
        "far part of the quad ran off the wall and is masked. Bounded over the lit quad within the wall, k matches c "
        "(to 0.002: c is taken at pixel centres) in "
        "every frame above.\n"
     << "- **The counter is not blind.** The naive third row [0 0 1 0] "
     << (naive_always_fails ? "clipped at least a quarter of the counted pixels in every oblique frame"
                            : "did not fail in every oblique frame")
     << "; the gpu test also checks a negated row (order reversed) and aligned z-fighting at 0.01 mm.\n";
  md.close();
  csv.close();
  std::cout << summary.str() << '\n' << gaps.str();
  return bench::draw_plot(out, "oblique-depth") ? 0 : 1;
}
