// Depth-of-field benchmark (docs/design.md, "Depth of field by optics"):
// the focused/defocused projector pair of configs/dof-pair.json against the ideal
// image (each pixel blurred by its own circle c_r · c_max) over a focal sweep,
// beside the all-in-focus image and a computational gather DOF on one node
// (a GLSL pass written here); the precision of c_r from a 24-bit or 32F depth
// buffer at far/near = 10⁴; and each method's time per frame. Writes dof.md,
// dof.csv, dof.png (the plot) and dof-images.png to --out.
//
//   optique-bench-dof [--out DIR] [--runs R] [--frames F] [--config FILE]

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bench_options.h"
#include "dof_experiment.h"
#include "draw_plot.h"
#include "image/compare.h"
#include "image/convert.h"
#include "image/image_io.h"
#include "number_text.h"
#include "render/gl_context.h"
#include "render/gl_objects.h"
#include "shaders.h"
#include "spread.h"

namespace {

using namespace optique;
using namespace optique::bench;
using namespace optique::bench::dof;

constexpr int kMaxReach = 62;
// A pixel sees an object when its exact depth is this close to the object's
// centre: the slabs are 3 cm deep and at least 1 m apart.
constexpr double kSameObject = 0.25;  // the gather's largest disc radius (c_max ≤ 62.5 px)

// The texture a SceneRenderer left bound on `unit` after drawing. Its output pass
// binds the rendered colour on unit 0 and the depth on unit 3; reading them in
// place keeps a copy out of the timed gather. Checked by format and size, so a
// change in the renderer fails here rather than gathering garbage.
GLuint bound_texture(int unit, std::initializer_list<GLenum> formats, int width, int height) {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  GLint name = 0;
  glGetIntegerv(GL_TEXTURE_BINDING_2D, &name);
  glActiveTexture(GL_TEXTURE0);
  GLint format = 0;
  GLint w = 0;
  GLint h = 0;
  if (name != 0) {
    glGetTextureLevelParameteriv(static_cast<GLuint>(name), 0, GL_TEXTURE_INTERNAL_FORMAT, &format);
    glGetTextureLevelParameteriv(static_cast<GLuint>(name), 0, GL_TEXTURE_WIDTH, &w);
    glGetTextureLevelParameteriv(static_cast<GLuint>(name), 0, GL_TEXTURE_HEIGHT, &h);
  }
  if (name == 0 || std::find(formats.begin(), formats.end(), static_cast<GLenum>(format)) == formats.end() ||
      w != width || h != height) {
    throw std::runtime_error("texture unit " + std::to_string(unit) +
                             " does not hold the renderer's image (SceneRenderer's output pass changed?)");
  }
  return static_cast<GLuint>(name);
}

// The gather DOF pass: the rendered image and its depth in, the blurred image in
// a float target of the same size.
class Gather {
 public:
  Gather(int width, int height, double c_max) : width_(width), height_(height) {
    // The largest circle's discs, as optics::disc_blur splits them.
    const double s = c_max - 0.5;
    const int inner = s > 0.0 ? static_cast<int>(std::floor(s)) : 0;
    reach_ = s > 0.0 ? inner + (s - inner > 0.0 ? 1 : 0) : 0;
    if (reach_ > kMaxReach) throw std::runtime_error("c_max too large for the gather");
    std::array<float, 64> inv_count{};
    for (int r = 0; r < 64; ++r) {
      long count = 0;
      for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) count += dx * dx + dy * dy <= r * (r + 1) ? 1 : 0;
      }
      inv_count[static_cast<std::size_t>(r)] = 1.0f / static_cast<float>(count);
    }
    auto program = render::glo::link_program(shaders::fullscreen_vert, shaders::gather_frag);
    if (!program) throw std::runtime_error("gather: " + program.error());
    program_ = std::move(program).value();
    glProgramUniform1f(program_.get(), glGetUniformLocation(program_.get(), "c_max"), static_cast<float>(c_max));
    glProgramUniform1i(program_.get(), glGetUniformLocation(program_.get(), "reach"), reach_);
    glProgramUniform1fv(program_.get(), glGetUniformLocation(program_.get(), "inv_count"), 64, inv_count.data());
    target_ = render::glo::make_texture();
    glTextureStorage2D(target_.get(), 1, GL_RGBA32F, width, height);
    framebuffer_ = render::glo::make_framebuffer();
    glNamedFramebufferTexture(framebuffer_.get(), GL_COLOR_ATTACHMENT0, target_.get(), 0);
    if (glCheckNamedFramebufferStatus(framebuffer_.get(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("gather framebuffer incomplete");
    }
    vertex_array_ = render::glo::make_vertex_array();
  }

  // Runs on what the renderer drew last and waits for the GPU.
  void run(GLuint rendered, GLuint depth, const optics::CocFromWindowDepth& mapping, bool normalized) {
    glProgramUniform4f(program_.get(), glGetUniformLocation(program_.get(), "coc"), static_cast<float>(mapping.k),
                       static_cast<float>(mapping.focal), static_cast<float>(mapping.lo),
                       static_cast<float>(mapping.hi));
    glProgramUniform1i(program_.get(), glGetUniformLocation(program_.get(), "normalized"), normalized ? 1 : 0);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
    glViewport(0, 0, width_, height_);
    glDisable(GL_DEPTH_TEST);
    glUseProgram(program_.get());
    glBindTextureUnit(0, rendered);
    glBindTextureUnit(1, depth);
    glBindVertexArray(vertex_array_.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glFinish();
  }

  [[nodiscard]] image::FloatImage read() const {
    image::FloatImage image(width_, height_, 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer_.get());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, image.pixels.data());
    image::flip_rows(image);
    return image;
  }

  [[nodiscard]] int reach() const { return reach_; }

 private:
  int width_;
  int height_;
  int reach_ = 0;
  render::glo::Program program_;
  render::glo::Texture target_;
  render::glo::Framebuffer framebuffer_;
  render::glo::VertexArray vertex_array_;
};

// Its tables say ∞ for a PSNR of equal images.
std::string cell(double v, int decimals) { return bench::fixed(v, decimals, "∞"); }

std::string signed_ms(double v) { return (v < 0.0 ? "−" : "+") + cell(std::abs(v), 2) + " ms"; }

std::string sci(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.2g", v);
  return text;
}

// PSNR (luma, peak 1) of `image` against the ideal over the pixels `where` accepts.
double psnr(const image::FloatImage& image, const image::FloatImage& ideal,
            const std::function<bool(int, int)>& where) {
  return image::psnr_luma_where(image, ideal, where);
}

// An object's part of the image: the pixels that see it, grown by the largest
// circle, so that its blur's spill onto what lies around it counts too.
std::vector<unsigned char> region_of(const ExactDepth& exact, double object_depth, double grow) {
  const int w = exact.depth.width;
  const int h = exact.depth.height;
  std::vector<unsigned char> sees(static_cast<std::size_t>(w) * h, 0);
  for (std::size_t i = 0; i < sees.size(); ++i) {
    sees[i] = std::abs(exact.depth.pixels[i] - object_depth) < kSameObject ? 1 : 0;
  }
  const int g = static_cast<int>(std::ceil(grow));
  std::vector<unsigned char> region(sees.size(), 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (sees[static_cast<std::size_t>(y) * w + x] == 0) continue;
      for (int dy = -g; dy <= g; ++dy) {
        for (int dx = -g; dx <= g; ++dx) {
          const int nx = x + dx;
          const int ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h || dx * dx + dy * dy > g * g) continue;
          region[static_cast<std::size_t>(ny) * w + nx] = 1;
        }
      }
    }
  }
  return region;
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Copies `image` (linear, scaled by `gain` for display) sRGB-encoded into
// `target` (RGB) at (x0, y0).
void paste(image::ByteImage& target, const image::FloatImage& image, float gain, int x0, int y0) {
  image::FloatImage bright = image;
  for (std::size_t i = 0; i < bright.pixels.size(); ++i) {
    if (i % 4 != 3) bright.pixels[i] *= gain;
  }
  const image::ByteImage encoded = image::encode_srgb(bright);
  for (int y = 0; y < encoded.height; ++y) {
    for (int x = 0; x < encoded.width; ++x) {
      if (x0 + x >= target.width || y0 + y >= target.height) continue;
      for (int c = 0; c < 3; ++c) target.at(x0 + x, y0 + y, c) = encoded.at(x, y, c);
    }
  }
}

struct Row {  // one focal depth
  double b = 0.0;
  Scores scores16;
  double pair8 = 0.0;
  double pair8_away = 0.0;
  double gather = 0.0;  // normalized
  double gather_away = 0.0;
  double exact_gather = 0.0;  // disc weights, unnormalized
  double exact_gather_away = 0.0;
};

struct ObjectScore {
  double b = 0.0;
  double depth = 0.0;
  double coc = 0.0;
  int pixels = 0;
  double sharp = 0.0;
  double pair = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  optique::bench::BenchOptions app{"optique depth-of-field benchmark"};
  std::string out = "docs/bench";
  std::string config = std::string(OPTIQUE_SOURCE_DIR) + "/configs/dof-pair.json";
  int runs = 5;
  int frames = 12;
  double image_focus = 2.5;
  app.option("--out", out, "folder for dof.md, dof.csv, dof.png and dof-images.png");
  app.option("--config", config, "the installation (a focus and a defocus projector)");
  app.option("--runs", runs, "timing runs; a cell is the median over runs with their min–max");
  app.option("--frames", frames, "frames per run, each method once per frame in rotating order");
  app.option("--image-focus", image_focus, "focal depth of the images in dof-images.png (m)");
  if (const std::optional<int> status = app.parse(argc, argv)) return *status;

  try {
    auto context = render::make_headless_context();
    if (!context) throw std::runtime_error(context.error());
    const std::string gl = context.value()->renderer_name();
    auto loaded = load_setup(config);
    if (!loaded) throw std::runtime_error(loaded.error());
    const PairSetup& setup = loaded.value();
    auto exact_result = exact_depth(setup);
    if (!exact_result) throw std::runtime_error(exact_result.error());
    const ExactDepth& exact = exact_result.value();
    const std::vector<double> sweep = focal_sweep(setup);
    auto pair16_result = Pair::create(setup, 16);
    if (!pair16_result) throw std::runtime_error(pair16_result.error());
    auto pair8_result = Pair::create(setup, 8);
    if (!pair8_result) throw std::runtime_error(pair8_result.error());
    Pair& pair16 = *pair16_result.value();
    Pair& pair8 = *pair8_result.value();
    const int width = exact.depth.width;
    const int height = exact.depth.height;
    Gather gather(width, height, setup.c_max);
    pair16.draw_plain();
    const GLuint rendered_texture = bound_texture(0, {GL_RGBA16F, GL_RGBA32F}, width, height);
    const GLuint depth_texture = bound_texture(3, {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT24}, width, height);

    std::filesystem::create_directories(out);
    std::ofstream csv(out + "/dof.csv");
    csv << "renderer,table,focal_depth_m,subject,method,metric,value\n";
    auto put = [&](const std::string& table, double b, const std::string& subject, const std::string& method,
                   const std::string& metric, double value) {
      csv << '"' << gl << "\"," << table << ',' << b << ',' << subject << ',' << method << ',' << metric << ',' << value
          << '\n';
    };

    // ---- Image quality over the sweep.
    std::vector<Row> rows;
    std::vector<ObjectScore> objects;
    float brightest = 0.0f;
    image::FloatImage shown_sharp;
    image::FloatImage shown_pair;
    image::FloatImage shown_ideal;
    image::FloatImage shown_gather;
    double shown_b = sweep.front();
    for (const double b : sweep) {
      if (std::abs(b - image_focus) < std::abs(shown_b - image_focus)) shown_b = b;
    }
    for (const double b : sweep) {
      auto f16 = pair16.frame(b, exact);
      if (!f16) throw std::runtime_error(f16.error());
      auto f8 = pair8.frame(b, exact);
      if (!f8) throw std::runtime_error(f8.error());
      const FocalFrame& f = f16.value();
      for (std::size_t i = 0; i < f.rendered.pixels.size(); ++i) {
        if (i % 4 != 3) brightest = std::max(brightest, f.rendered.pixels[i]);
      }
      const auto all = [](int, int) { return true; };
      const auto away = [&f](int x, int y) { return f.coc.at(x, y, 0) > kAwayFromFocus; };
      Row row;
      row.b = b;
      row.scores16 = f.scores;
      row.pair8 = psnr(f8.value().composite, f.ideal, all);
      row.pair8_away = psnr(f8.value().composite, f.ideal, away);
      pair16.draw_plain();
      gather.run(rendered_texture, depth_texture, pair16.mapping(b), true);
      const image::FloatImage gathered = gather.read();
      row.gather = psnr(gathered, f.ideal, all);
      row.gather_away = psnr(gathered, f.ideal, away);
      gather.run(rendered_texture, depth_texture, pair16.mapping(b), false);
      const image::FloatImage exact_gathered = gather.read();
      row.exact_gather = psnr(exact_gathered, f.ideal, all);
      row.exact_gather_away = psnr(exact_gathered, f.ideal, away);
      rows.push_back(row);
      const std::string bs = cell(b, 3);
      for (const auto& [method, all_db, away_db] :
           {std::tuple{"all-in-focus", f.scores.sharp, f.scores.sharp_away},
            std::tuple{"pair-16bit", f.scores.pair, f.scores.pair_away},
            std::tuple{"pair-8bit", row.pair8, row.pair8_away},
            std::tuple{"gather-normalized", row.gather, row.gather_away},
            std::tuple{"gather-disc-weights", row.exact_gather, row.exact_gather_away}}) {
        put("psnr", b, "all-pixels", method, "psnr_luma_db", all_db);
        put("psnr", b, "away-from-focus", method, "psnr_luma_db", away_db);
      }
      put("psnr", b, "away-from-focus", "", "pixels", f.scores.away_pixels);
      for (const double depth : setup.object_depths) {
        const auto region = region_of(exact, depth, setup.c_max);
        const auto in = [&](int x, int y) { return region[static_cast<std::size_t>(y) * width + x] != 0; };
        ObjectScore o;
        o.b = b;
        o.depth = depth;
        // The c_r the object's pixels have (its front face, mostly), not its centre's:
        // near c_r = ½ / c_max the 1.5 cm between them decides whether the ideal blurs at all.
        std::vector<double> seen_coc;
        for (std::size_t i = 0; i < f.coc.pixels.size(); ++i) {
          if (std::abs(exact.depth.pixels[i] - depth) < kSameObject) seen_coc.push_back(f.coc.pixels[i]);
        }
        o.coc = seen_coc.empty() ? optics::relative_coc(depth, b, setup.range) : spread(seen_coc).median;
        o.pixels = static_cast<int>(std::count(region.begin(), region.end(), 1));
        o.sharp = psnr(f.rendered, f.ideal, in);
        o.pair = psnr(f.composite, f.ideal, in);
        objects.push_back(o);
        const std::string subject = "object-at-" + cell(depth, 2) + "m";
        put("object", b, subject, "", "coc", o.coc);
        put("object", b, subject, "all-in-focus", "psnr_luma_db", o.sharp);
        put("object", b, subject, "pair-16bit", "psnr_luma_db", o.pair);
      }
      if (b == shown_b) {
        shown_sharp = f.rendered;
        shown_pair = f.composite;
        shown_ideal = f.ideal;
        shown_gather = gathered;
      }
      std::cout << "b " << bs << " m: all-in-focus " << cell(f.scores.sharp_away, 2) << ", pair "
                << cell(f.scores.pair_away, 2) << " (8-bit " << cell(row.pair8_away, 2) << "), gather "
                << cell(row.gather_away, 2) << ", disc-weight gather " << cell(row.exact_gather_away, 2)
                << " dB (away from focus)" << std::endl;
    }

    // ---- c_r from the depth buffer.
    struct PrecisionCase {
      double near;
      double far;
      render::DepthFormat format;
      const char* name;
    };
    const std::vector<PrecisionCase> precision_cases{
        {setup.frustum_near, setup.frustum_far, render::DepthFormat::fixed24, "24-bit"},
        {setup.frustum_near, setup.frustum_far, render::DepthFormat::float32, "32F"},
        {0.01, 100.0, render::DepthFormat::fixed24, "24-bit"},
        {0.01, 100.0, render::DepthFormat::float32, "32F"}};
    std::ostringstream precision_table;
    precision_table
        << "| near / far (m) | far/near | depth | pixels (on silhouettes) | \\|Δz′\\| max (2⁻²⁴) | "
           "c_r from read_depth(): max / mean | c_r from the output pass: max / mean (lit pixel × b samples) | "
           "shader vs CPU max |\n|---|---:|---|---:|---:|---:|---:|---:|\n";
    double worst_buffer = 0.0;
    double worst_output = 0.0;
    double worst_output_vs_cpu = 0.0;
    for (const PrecisionCase& c : precision_cases) {
      auto p = measure_precision(setup, exact, c.format, c.near, c.far, sweep);
      if (!p) throw std::runtime_error(p.error());
      const Precision& q = p.value();
      worst_buffer = std::max(worst_buffer, q.buffer_max);
      worst_output = std::max(worst_output, q.output_max);
      worst_output_vs_cpu = std::max(worst_output_vs_cpu, q.output_vs_buffer_max);
      precision_table << "| " << cell(c.near, 2) << " / " << cell(c.far, 0) << " | " << cell(c.far / c.near, 0) << " | "
                      << c.name << " | " << q.counted << " (" << q.excluded << ") | " << cell(q.window_steps_max, 2)
                      << " | " << sci(q.buffer_max) << " / " << sci(q.buffer_mean) << " | " << sci(q.output_max)
                      << " / " << sci(q.output_mean) << " (" << q.output_counted << ") | "
                      << sci(q.output_vs_buffer_max) << " |\n";
      const std::string subject = "near-" + cell(c.near, 2) + "-far-" + cell(c.far, 0);
      put("precision", 0.0, subject, c.name, "window_steps_max", q.window_steps_max);
      put("precision", 0.0, subject, c.name, "coc_buffer_max", q.buffer_max);
      put("precision", 0.0, subject, c.name, "coc_buffer_mean", q.buffer_mean);
      put("precision", 0.0, subject, c.name, "coc_output_max", q.output_max);
      put("precision", 0.0, subject, c.name, "coc_output_mean", q.output_mean);
      put("precision", 0.0, subject, c.name, "coc_shader_vs_cpu_max", q.output_vs_buffer_max);
      std::cout << subject << ' ' << c.name << ": c_r error max " << sci(q.buffer_max) << ", output pass "
                << sci(q.output_max) << std::endl;
    }

    // ---- Time per frame: every method once per frame, in rotating order.
    enum Method { kFull, kFocus, kDefocus, kGather, kMethods };
    const std::array<const char*, kMethods> names{"full render", "focus node", "defocus node", "gather DOF"};
    std::array<std::vector<double>, kMethods + 1> run_medians;  // + the pair (the slower node per frame)
    auto time_method = [&](int m, double b) {
      const auto start = Clock::now();
      switch (m) {
        case kFull:
          pair16.draw_plain();
          break;
        case kFocus:
          pair16.draw_focus(b);
          break;
        case kDefocus:
          pair16.draw_defocus(b);
          break;
        default:
          pair16.draw_plain();
          gather.run(rendered_texture, depth_texture, pair16.mapping(b), true);
          break;
      }
      return ms_since(start);
    };
    for (int m = 0; m < kMethods; ++m) (void)time_method(m, sweep.front());  // shaders compile lazily
    for (int r = 0; r < runs; ++r) {
      std::array<std::vector<double>, kMethods + 1> times;
      for (int k = 0; k < frames; ++k) {
        const double b = sweep[static_cast<std::size_t>(k) % sweep.size()];
        std::array<double, kMethods> t{};
        for (int i = 0; i < kMethods; ++i) {
          const int m = (i + k + r) % kMethods;
          t[static_cast<std::size_t>(m)] = time_method(m, b);
        }
        for (int m = 0; m < kMethods; ++m) times[static_cast<std::size_t>(m)].push_back(t[static_cast<std::size_t>(m)]);
        times[kMethods].push_back(std::max(t[kFocus], t[kDefocus]));
      }
      for (int m = 0; m <= kMethods; ++m) {
        run_medians[static_cast<std::size_t>(m)].push_back(spread(times[static_cast<std::size_t>(m)]).median);
      }
    }
    std::array<Spread, kMethods + 1> timing;
    for (int m = 0; m <= kMethods; ++m) {
      timing[static_cast<std::size_t>(m)] = spread(run_medians[static_cast<std::size_t>(m)]);
      const std::string method = m == kMethods ? "pair (slower node)" : names[static_cast<std::size_t>(m)];
      put("timing", 0.0, std::to_string(width) + "x" + std::to_string(height), method, "ms_median",
          timing[static_cast<std::size_t>(m)].median);
      put("timing", 0.0, std::to_string(width) + "x" + std::to_string(height), method, "ms_min",
          timing[static_cast<std::size_t>(m)].low);
      put("timing", 0.0, std::to_string(width) + "x" + std::to_string(height), method, "ms_max",
          timing[static_cast<std::size_t>(m)].high);
    }

    // ---- Summaries.
    auto mean_of = [&](const std::function<double(const Row&)>& f) {
      double sum = 0.0;
      for (const Row& row : rows) sum += f(row);
      return sum / static_cast<double>(rows.size());
    };
    auto min_of = [&](const std::function<double(const Row&)>& f) {
      double least = std::numeric_limits<double>::infinity();
      for (const Row& row : rows) least = std::min(least, f(row));
      return least;
    };
    const double full_ms = timing[kFull].median;
    std::ostringstream timing_table;
    timing_table << "| method (" << width << "×" << height << ", c_max " << cell(setup.c_max, 1)
                 << " px) | ms per frame | over the full render | PSNR vs ideal, away from focus: mean / worst over "
                    "the sweep (dB) |\n|---|---:|---:|---:|\n";
    auto timing_row = [&](const std::string& what, const Spread& s, const std::string& psnr_text) {
      timing_table << "| " << what << " | " << cell(s, 2) << " | "
                   << (s.median == full_ms ? "—" : signed_ms(s.median - full_ms)) << " | " << psnr_text << " |\n";
    };
    timing_row("full render alone (all-in-focus)", timing[kFull],
               cell(mean_of([](const Row& r) { return r.scores16.sharp_away; }), 2) + " / " +
                   cell(min_of([](const Row& r) { return r.scores16.sharp_away; }), 2));
    timing_row("focus node: render + output pass with (1 − c_r)", timing[kFocus], "");
    timing_row("defocus node: render + output pass with c_r", timing[kDefocus], "");
    timing_row("**pair** (each frame the slower node: two machines in parallel)", timing[kMethods],
               cell(mean_of([](const Row& r) { return r.scores16.pair_away; }), 2) + " / " +
                   cell(min_of([](const Row& r) { return r.scores16.pair_away; }), 2));
    timing_row(
        "**gather DOF** on one node: render + gather pass (" + std::to_string(2 * gather.reach() + 1) + "² taps)",
        timing[kGather],
        cell(mean_of([](const Row& r) { return r.gather_away; }), 2) + " / " +
            cell(min_of([](const Row& r) { return r.gather_away; }), 2) + " (normalized); disc weights " +
            cell(min_of([](const Row& r) { return r.exact_gather_away; }), 1) + " at worst");

    std::ostringstream psnr_table;
    psnr_table << "| b (m) | pixels away from focus | all-in-focus | pair 16-bit | pair 8-bit | gather (normalized) | "
                  "gather (disc weights) | pair − all-in-focus |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    double least_margin = std::numeric_limits<double>::infinity();
    double least_margin_b = 0.0;
    for (const Row& r : rows) {
      const double margin = r.scores16.pair_away - r.scores16.sharp_away;
      if (margin < least_margin) {
        least_margin = margin;
        least_margin_b = r.b;
      }
      psnr_table << "| " << cell(r.b, 3) << " | " << r.scores16.away_pixels << " | " << cell(r.scores16.sharp, 2)
                 << " / " << cell(r.scores16.sharp_away, 2) << " | " << cell(r.scores16.pair, 2) << " / "
                 << cell(r.scores16.pair_away, 2) << " | " << cell(r.pair8, 2) << " / " << cell(r.pair8_away, 2)
                 << " | " << cell(r.gather, 2) << " / " << cell(r.gather_away, 2) << " | " << cell(r.exact_gather, 1)
                 << " / " << cell(r.exact_gather_away, 1) << " | " << cell(r.scores16.pair - r.scores16.sharp, 2)
                 << " / " << cell(margin, 2) << " |\n";
    }

    // The pair's gain on each object, by the object's c_r. Below a radius of half a
    // pixel (c_r < ½ / c_max) the ideal leaves the object's pixels as they are, so
    // all-in-focus is exact there up to neighbours' spill and only the pair's loss
    // is worth a number.
    const double sharp_limit = 0.5 / setup.c_max;
    const std::vector<double> bins{0.0, sharp_limit, 0.125, 0.25, 0.5, 1.0001};
    std::ostringstream object_table;
    object_table << "| object's c_r (median over its pixels) | (object, b) cases | all-in-focus: median | pair: median "
                    "(dB) | pair − "
                    "all-in-focus: mean | min | max (dB) |\n|---|---:|---:|---:|---:|---:|---:|\n";
    struct Bin {
      double low = 0.0;
      double high = 0.0;
      int cases = 0;
      double mean_gain = 0.0;
      double least_gain = 0.0;
      double most_gain = 0.0;
    };
    std::vector<Bin> gain_bins;
    for (std::size_t i = 0; i + 1 < bins.size(); ++i) {
      std::vector<double> sharp;
      std::vector<double> paired;
      std::vector<double> gains;
      for (const ObjectScore& o : objects) {
        if (o.coc < bins[i] || o.coc >= bins[i + 1]) continue;
        sharp.push_back(o.sharp);
        paired.push_back(o.pair);
        gains.push_back(o.pair - o.sharp);
      }
      Bin bin{bins[i], std::min(bins[i + 1], 1.0), static_cast<int>(gains.size())};
      object_table << "| " << cell(bin.low, 4) << " – " << cell(bin.high, 4) << " | " << bin.cases << " | ";
      if (gains.empty()) {
        object_table << " | | | | |\n";
        continue;
      }
      object_table << cell(spread(sharp).median, 2) << " | " << cell(spread(paired).median, 2) << " | ";
      if (i == 0) {
        object_table << "(ideal ≈ all-in-focus) | | |\n";
        continue;
      }
      double sum = 0.0;
      for (double g : gains) sum += g;
      bin.mean_gain = sum / static_cast<double>(gains.size());
      bin.least_gain = *std::min_element(gains.begin(), gains.end());
      bin.most_gain = *std::max_element(gains.begin(), gains.end());
      gain_bins.push_back(bin);
      object_table << cell(bin.mean_gain, 2) << " | " << cell(bin.least_gain, 2) << " | " << cell(bin.most_gain, 2)
                   << " |\n";
    }

    // ---- dof-images.png: the part of the image with the objects and their blur,
    // at full resolution (dof.png, the plot, is drawn from dof.csv at the end).
    int seen_x0 = width;
    int seen_x1 = 0;
    int seen_y0 = height;
    int seen_y1 = 0;
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if (!std::isfinite(exact.depth.at(x, y, 0))) continue;
        seen_x0 = std::min(seen_x0, x);
        seen_x1 = std::max(seen_x1, x);
        seen_y0 = std::min(seen_y0, y);
        seen_y1 = std::max(seen_y1, y);
      }
    }
    const int pad = static_cast<int>(std::ceil(setup.c_max)) + 4;
    const int crop_x = std::max(0, seen_x0 - pad);
    const int crop_y = std::max(0, seen_y0 - pad);
    const int tile_w = std::max(1, std::min(width, seen_x1 + pad + 1) - crop_x);
    const int tile_h = std::max(1, std::min(height, seen_y1 + pad + 1) - crop_y);
    const auto crop = [&](const image::FloatImage& image) {
      return image::crop(image, crop_x, crop_y, tile_w, tile_h);
    };
    // White margins of 10 px around and between the tiles.
    const int canvas_w = 4 * (tile_w + 10) + 10;
    image::ByteImage canvas(canvas_w, 2 * (tile_h + 10) + 10, 3);
    std::fill(canvas.pixels.begin(), canvas.pixels.end(), std::uint8_t{255});
    const int tiles_y = 10;
    const float gain = brightest > 0.0f ? 0.9f / brightest : 1.0f;
    constexpr float kErrorGain = 8.0f;  // the differences, brighter still
    const std::array<const image::FloatImage*, 4> shown{&shown_sharp, &shown_pair, &shown_ideal, &shown_gather};
    for (std::size_t i = 0; i < shown.size(); ++i) {
      const int x0 = 10 + static_cast<int>(i) * (tile_w + 10);
      paste(canvas, crop(*shown[i]), gain, x0, tiles_y);
      if (shown[i] != &shown_ideal) {
        paste(canvas, crop(image::difference(*shown[i], shown_ideal, kErrorGain)), gain, x0, tiles_y + tile_h + 10);
      }
    }
    if (auto written = image::write_png(out + "/dof-images.png", canvas); !written) {
      throw std::runtime_error(written.error());
    }

    // ---- dof.md
    double worst_b_coc_low = 1.0;
    double worst_b_coc_high = 0.0;
    for (const ObjectScore& o : objects) {
      if (o.b != least_margin_b) continue;
      worst_b_coc_low = std::min(worst_b_coc_low, o.coc);
      worst_b_coc_high = std::max(worst_b_coc_high, o.coc);
    }
    double max_8bit_loss = 0.0;
    double max_gather_loss = 0.0;
    std::string gather_worse_at;  // the focal depths where the normalized gather is worse than the pair
    for (const Row& r : rows) {
      max_8bit_loss = std::max(max_8bit_loss, std::abs(r.scores16.pair_away - r.pair8_away));
      max_gather_loss = std::max(max_gather_loss, r.scores16.pair_away - r.gather_away);
      if (r.gather_away < r.scores16.pair_away) gather_worse_at += (gather_worse_at.empty() ? "" : ", ") + cell(r.b, 2);
    }
    Bin low_bin;  // c_r from ½ / c_max to 0.125
    if (!gain_bins.empty()) low_bin = gain_bins.front();
    const bool software = gl.find("llvmpipe") != std::string::npos;
    const double k_precise = optics::coc_from_window_depth(setup.range.near, setup.range, 0.01, 100.0).k;
    double buffer_bound_8bit = 1.0 / 255.0;
    std::ofstream md(out + "/dof.md");
    md << "# Depth of field by a focused and a defocused projector, measured\n\n"
       << "Generated by `optique-bench-dof` on " << gl
       << ". [docs/design.md](../design.md) (Majumder & Welch, depth of field by optics) gives the pair: the focus "
          "projector shows "
          "(1 − c_r)·I, the defocus projector c_r·I through optics that blur by the largest circle of confusion "
          "c_max, so the sum on the screen approximates the ideal image in which every pixel is blurred by its own "
          "circle c_r·c_max. This measures how close it gets, what the depth buffer does to c_r, and what the pair "
          "costs beside a computational DOF.\n\n"
       << "**Setup.** `configs/dof-pair.json`: the depth-stack scene (five 0.3 m slabs at eye depths ";
    for (std::size_t i = 0; i < setup.object_depths.size(); ++i) {
      md << (i == 0 ? "" : ", ") << cell(setup.object_depths[i], 1);
    }
    md << " m over a black background), the viewer's eye 2 m before a 3.2 × 1.8 m screen, two aligned " << width << "×"
       << height << " projectors (projector pixels = screen pixels), c_r from near " << setup.range.near << " m to far "
       << setup.range.far << " m, c_max = " << cell(setup.c_max, 1) << " px, frustum near/far " << setup.frustum_near
       << " / " << setup.frustum_far
       << " m (the viewer's defaults). Both nodes are SceneRenderers set up as `GlRenderer::configure` sets up a "
          "focus/defocus projector (single pass, the projector's output stage with its share); the projectors' "
          "response is sRGB with a 16-bit signal (quantization out of the way) or 8 bits (a common projector). On "
          "the screen: focus light + `disc_blur(defocus light, c_max)` (the defocused optics; the master's "
          "compositor does the same). **Ideal**: the full render spread per pixel over c_r(z)·c_max "
          "(`scatter_defocus`), z exact: the ray from the eye through each pixel centre cast against the scene "
          "(`RayCaster`), depth along the screen's normal; a ray that meets nothing is as far as the range's far "
          "end. **All-in-focus**: the full render. **Gather DOF**: a GLSL pass on one node (in this bench): every "
          "pixel gathers from the "
       << 2 * gather.reach() + 1
       << "² pixels within c_max the share each one's own "
          "disc (c_r from the depth buffer, the same discs as `scatter_defocus`) puts on it; *normalized* divides "
          "by the shares received (the usual real-time form), *disc weights* does not, which is the ideal itself "
          "computed on the GPU (a check of the pass). It reads the renderer's colour and depth textures in place, "
          "so its time is GPU work only.\n\n"
       << "**Metric.** PSNR of Rec. 601 luma against the ideal, peak 1 (the projector's white). The scene is dim "
          "(brightest pixel "
       << cell(brightest, 3)
       << "), so absolute values are high; differences between methods at the same b are ratios of squared error "
          "and do not depend on the peak. *All pixels*, and *away from focus*: pixels whose exact c_r > "
       << kAwayFromFocus
       << " (a blur over 0.4 px; at c_r ≈ 0 both images are the render itself). Pixels with no error count in "
          "both and shift both methods alike.\n\n"
       << "## PSNR over the focal sweep\n\nEach cell: all pixels / away from focus (dB).\n\n"
       << psnr_table.str() << "\n"
       << "## The pair's gain by the object's c_r\n\nPer object and b: PSNR over the pixels that see the object, "
          "grown by c_max (its blur's spill); pair (16-bit) minus all-in-focus.\n\n"
       << object_table.str() << "\n"
       << "## c_r from the depth buffer\n\nc_r of the depth buffer against c_r of the exact depth, over every b "
          "of the sweep and the pixels off silhouettes (where a 3×3 neighbourhood sees one object). *From "
          "read_depth()*: `relative_coc(float window depth, mapping)`, the shader's arithmetic on the CPU. *From "
          "the output pass*: 1 − focus/I read back from the focus projector's light (16-bit signal) in the "
          "channel with the most light where I > 10⁻³; it carries the 16-bit signal's step, which at dim pixels is "
          "larger than the depth's, so it bounds the shader's c_r only to about 10⁻⁴. 8-bit output resolves "
          "1/255 = "
       << sci(buffer_bound_8bit) << ".\n\n"
       << precision_table.str() << "\n"
       << "## Time per frame\n\nOne process, one GL context, " << runs << " runs of " << frames
       << " frames; every frame runs each method once, in an order that rotates from frame to frame, cycling "
          "through the sweep's b; each cell is the median over runs of the per-run median, with the min–max over "
          "runs. Each method ends with glFinish. The nodes of the pair run on two machines at once, so the pair's "
          "frame time is the slower node's, taken frame by frame.\n\n"
       << timing_table.str() << "\n"
       << "## Plots\n\n![PSNR away from focus against the focal depth b; the pair's gain over all-in-focus per "
          "object and b against the object's c_r](dof.png)\n\n"
          "The disc-weight gather is the ideal to float rounding and is left out of the plot. `dof-images.png`, "
          "top row, at b = "
       << cell(shown_b, 2) << " m, the " << tile_w << "×" << tile_h
       << " pixels around the objects, full resolution, brightened ×" << cell(gain, 1)
       << ": all-in-focus, the pair on the screen (16-bit), the ideal, the normalized gather. Bottom row: each "
          "one's difference from the ideal, ×"
       << cell(kErrorGain * gain, 0) << " (none under the ideal).\n\n![the images at b = " << cell(shown_b, 2)
       << " m and their differences from the ideal](dof-images.png)\n\n"
       << "## Findings\n\n"
       << "- **The pair against all-in-focus.** Away from focus the pair is "
       << (least_margin > 0.0 ? "closer to the ideal at every b of the sweep, by "
                              : "not closer to the ideal at every b of the sweep: the difference is ")
       << cell(least_margin, 2) << " dB at least (b = " << cell(least_margin_b, 3) << " m) and "
       << cell(mean_of([](const Row& r) { return r.scores16.pair_away - r.scores16.sharp_away; }), 2)
       << " dB on average. At the worst b every object's c_r lies between " << cell(worst_b_coc_low, 2) << " and "
       << cell(worst_b_coc_high, 2)
       << ": the gain grows with c_r (table above), and that b has no object where the pair gains much. So the "
          "margin is clear but not large everywhere: "
       << (least_margin >= 3.0 ? "it stays above 3 dB." : "it does not reach 3 dB at every b.") << "\n"
       << "- **Why the gain is small at small c_r.** The pair's blur of a pixel is (1 − c_r) of it left sharp plus "
          "c_r spread over the largest circle; the ideal spreads all of it over a circle c_r times as large. Both "
          "move the same light off the pixel's centre, but the pair's is a sharp core with a faint wide skirt. "
          "For small c_r that is little different from the sharp image, so it gains little over it. Below "
          "c_r = ½ / c_max = "
       << cell(sharp_limit, 4)
       << " the ideal is the sharp image (a circle under half a pixel), while the pair's skirt is still c_max "
          "wide: there the pair can only lose. Just above it the ideal's circle is barely over half a pixel and "
          "the pair still mostly loses: objects at c_r "
       << cell(sharp_limit, 4) << "–0.125 gain " << cell(low_bin.mean_gain, 2) << " dB on average (from "
       << cell(low_bin.least_gain, 1) << " to " << cell(low_bin.most_gain, 1)
       << "). Such pixels count as away from focus (c_r > " << kAwayFromFocus
       << "); in this scene they are few beside the background's. Towards c_r = 1 the pair becomes the largest blur "
          "itself and approaches the "
          "ideal.\n"
       << "- **Bit depth.** The pair with 8-bit projectors is within " << cell(max_8bit_loss, 2)
       << " dB of the 16-bit pair at every b: the method's error, not quantization, sets the PSNR here (the sum "
          "of two 8-bit projectors also has more levels than one).\n"
       << "- **Gather DOF.** With the reference's own disc weights the gather is the ideal (PSNR over "
       << cell(min_of([](const Row& r) { return r.exact_gather_away; }), 0)
       << " dB: float rounding), so at this resolution a computational DOF can be exact. Normalized by the shares "
          "a pixel receives, it is wrong wherever those do not add to 1, i.e. where the circle changes abruptly "
          "across an edge: a sharp object's edge pixels also receive the blurred background's shares and are "
          "darkened (the rings in the bottom row), and a blurred object's edge pixels receive only part of a "
          "full share, are brightened back and keep a sharp silhouette instead of spreading. The latter makes it "
          "worse than the pair where blurred objects lie before a sharp background (b = "
       << gather_worse_at << " m, by up to " << cell(max_gather_loss, 1) << " dB).\n"
       << "- **Cost.** The output pass with the mask changes the focus node's frame time by "
       << signed_ms(timing[kFocus].median - full_ms) << " and the defocus node's by "
       << signed_ms(timing[kDefocus].median - full_ms) << " against the full render alone (whose runs spread over "
       << cell(timing[kFull].low, 2) << "–" << cell(timing[kFull].high, 2)
       << " ms): one depth fetch and the mask's arithmetic per pixel, in a pass every node runs anyway. The blur "
          "itself is done by the defocused projector's optics, so the pair's frame costs one node's render plus "
          "that mask, on two machines and two projectors. The gather costs "
       << cell(timing[kGather].median - full_ms, 1) << " ms more (" << cell(timing[kGather].median / full_ms, 1)
       << "× the full render) for its " << 2 * gather.reach() + 1 << "² taps per pixel, work that grows with c_max². "
       << (software ? "These are llvmpipe times (the CPU rasterizes, on a shared machine); a GPU is far faster at "
                      "both, but the ratio of work per pixel, one depth fetch against "
                    : "The ratio of work per pixel, one depth fetch against ")
       << 2 * (2 * gather.reach() + 1) * (2 * gather.reach() + 1) << " texel fetches, stands.\n"
       << "- **Depth precision.** c_r from the depth buffer is within " << sci(worst_buffer)
       << " of c_r of the exact depth at far/near = 10⁴ (near 0.01 m), against an 8-bit step of 1/255 = "
       << sci(buffer_bound_8bit)
       << ": it does not matter, and no fix is needed. It is k·|Δz′| with k = (1/n − 1/f)/(1/near − 1/far) = "
       << cell(k_precise, 0)
       << " at near 0.01 m and |Δz′| about one step of 2⁻²⁴ (the column above), i.e. about 10⁻⁵. 24-bit and 32F "
          "give the same numbers: with the standard mapping, depth beyond a few near distances lies in z′ ∈ "
          "[0.5, 1), where a float's spacing is 2⁻²⁴ like 24-bit fixed point's, and the vertex stage's float "
          "arithmetic rounds at that level anyway. It would reach 1/255 only at k ≈ 2²⁴/255 ≈ 6.6·10⁴, a near "
          "plane of about 17 µm for this c_r range. Were it to matter, the fix would be reversed depth (glClipControl "
          "with a [0, 1] clip range, a "
          "far-to-near projection and GREATER depth test) with a 32F buffer, which makes the spacing relative "
          "to depth; 32F alone buys nothing. The output pass's own c_r agrees with the CPU's to "
       << sci(worst_output_vs_cpu) << ", the read-back's rounding.\n"
       << "\nReproduce: `cmake --build build --target optique-bench-dof && build/bin/optique-bench-dof --out "
          "docs/bench`.\n";
    std::cout << psnr_table.str() << '\n'
              << object_table.str() << '\n'
              << precision_table.str() << '\n'
              << timing_table.str();
    md.close();
    csv.close();
    if (!bench::draw_plot(out, "dof")) return 1;
  } catch (const std::exception& e) {
    std::cerr << "optique-bench-dof: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
