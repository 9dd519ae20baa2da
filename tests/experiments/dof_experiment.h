#pragma once
// Depth of field by optics (docs/design.md, "Depth of field by optics"),
// measured: the installation of configs/dof-pair.json (the depth-stack scene, a
// focused and a defocused projector on one screen) rendered by the same
// SceneRenderer output stages the nodes use, the defocused projector's optics
// applied (optics::disc_blur by c_max), and the sum compared with the ideal image
// (every pixel spread over its own circle c_r(z) · c_max, z exact by ray casting:
// optics::scatter_defocus) and with the all-in-focus image. Also the precision
// of c_r taken from the depth buffer at a far/near ratio of 10⁴. Shared by the
// benchmark (optique-bench-dof: the sweep, the timings, the report) and the gpu
// test (the facts that must hold).

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "config/job.h"
#include "image/image.h"
#include "optics/defocus.h"
#include "render/projector_pipeline.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::bench::dof {

// Pixels whose exact c_r exceeds this are "away from the focal plane": there the
// ideal image differs from the sharp one by a blur of more than 0.4 px, so the
// pair has something to do. At c_r ≈ 0 the pair and the sharp image are alike.
inline constexpr double kAwayFromFocus = 0.05;

// The installation as the pair's nodes see it, from the config file.
struct PairSetup {
  scene::SceneDefinition scene;
  scene::SceneState state;     // every object at t = 0 (depth-stack does not move), the eye at t = 0
  config::ProjectorJob focus;  // as loaded, the projectors' sizes divided by the divisor
  config::ProjectorJob defocus;
  glm::dvec3 eye{0.0};
  double frustum_near = 0.0;  // the viewer's clip planes, as a node draws with them
  double frustum_far = 0.0;
  optics::CocRange range;             // depth_of_field near/far: where c_r reaches 1
  double c_max = 0.0;                 // the defocused optics' circle of confusion, projector pixels
  std::vector<double> object_depths;  // eye depth of every object's centre, nearest first
};

// Loads `config_path` (configs/dof-pair.json). A divisor > 1 draws the projectors
// at 1/divisor of their size and scales c_max with them, so that the blur covers
// the same part of the screen (for a faster test).
[[nodiscard]] Result<PairSetup> load_setup(const std::string& config_path, int divisor = 1);

// The focal depths of the sweep: the range's ends, every object's depth and points
// between them, nearest first.
[[nodiscard]] std::vector<double> focal_sweep(const PairSetup& setup);

// Exact eye depth (along the screen's normal) per projector pixel, by casting the
// ray from the eye through the pixel centre; +∞ where it meets nothing.
struct ExactDepth {
  image::FloatImage depth;  // 1 channel, top row first
  // 1 where the pixel's 3×3 neighbourhood sees more than one object (or object
  // and background): there the rasterizer's coverage at the centre decides, not
  // depth precision, so precision counts leave these out.
  std::vector<unsigned char> silhouette;
};
[[nodiscard]] Result<ExactDepth> exact_depth(const PairSetup& setup);

// The PSNRs of one focal depth, of luma (Rec. 601) with peak 1, against the ideal.
struct Scores {
  double pair = 0.0;       // the pair's composite, all pixels
  double sharp = 0.0;      // the all-in-focus image, all pixels
  double pair_away = 0.0;  // the same over the pixels with exact c_r > kAwayFromFocus
  double sharp_away = 0.0;
  int away_pixels = 0;
};

struct FocalFrame {
  double focal_depth = 0.0;
  image::FloatImage rendered;   // the full render, linear (the all-in-focus image)
  image::FloatImage focus;      // light the focus projector emits: (1 − c_r)·I
  image::FloatImage defocus;    // light the defocus projector emits, before its optics: c_r·I
  image::FloatImage composite;  // on the screen: focus + disc_blur(defocus, c_max)
  image::FloatImage ideal;      // scatter_defocus(rendered, c_r(exact z) · c_max)
  image::FloatImage coc;        // exact c_r per pixel, 1 channel
  Scores scores;
};

// PSNR of luma over the pixels with exact c_r > kAwayFromFocus (all pixels when
// `away` is false), +∞ when they agree there.
[[nodiscard]] double psnr_against(const image::FloatImage& image, const FocalFrame& frame, bool away);

// A frustum of the pair: the viewer's eye through the focus projector's region.
// The pair's two nodes and a plain one, each a SceneRenderer as the node sets it
// up (node/gl_renderer.cpp), on the current GL context.
class Pair {
 public:
  // `bits`: the projectors' signal depth (16 keeps quantization out of the
  // comparison, 8 is a common projector). Keeps a reference to `setup`, which
  // must outlive it. Fails when a renderer cannot be made.
  [[nodiscard]] static Result<std::unique_ptr<Pair>> create(const PairSetup& setup, int bits,
                                                            render::DepthFormat depth = render::DepthFormat::float32);

  // Renders focal depth `b` with all three, composes, and scores against the
  // ideal. `exact` from exact_depth(setup).
  [[nodiscard]] Result<FocalFrame> frame(double b, const ExactDepth& exact);

  // Draws one frame of each node for focal depth b (for timing): the plain full
  // render, the focus node and the defocus node; each returns when the GPU is done.
  void draw_plain();
  void draw_focus(double b);
  void draw_defocus(double b);
  // The output pass's c_r mapping for focal depth b with the viewer's frustum.
  [[nodiscard]] optics::CocFromWindowDepth mapping(double b) const;

 private:
  explicit Pair(const PairSetup& setup) : setup_(setup) {}
  const PairSetup& setup_;
  // Each built as its node would build it (render::ProjectorPipeline).
  std::unique_ptr<render::ProjectorPipeline> plain_;
  std::unique_ptr<render::ProjectorPipeline> focus_;
  std::unique_ptr<render::ProjectorPipeline> defocus_;
};

// How far c_r from the depth buffer is from c_r of the exact depth, over the
// pixels off silhouettes, for a frustum and depth format (docs/design.md's c_r in the
// window-depth form the output pass evaluates, optics::coc_from_window_depth).
struct Precision {
  int counted = 0;   // pixels off silhouettes
  int excluded = 0;  // on silhouettes
  // c_r the CPU computes from read_depth() with optics::relative_coc(float, mapping).
  double buffer_max = 0.0;
  double buffer_mean = 0.0;
  // Window depth itself: the largest |z'(buffer) − z'(exact)|, in steps of 2⁻²⁴.
  double window_steps_max = 0.0;
  // c_r the GL output pass used, read back from the focus projector's light:
  // 1 − focus / I in the channel with the most light, where that exceeds 1e-3.
  // Carries the half-float rounding of the stored light (≈ 2⁻¹¹ relative).
  // Means and output_counted are over (pixel, focal depth) pairs.
  int output_counted = 0;
  double output_max = 0.0;
  double output_mean = 0.0;
  double output_vs_buffer_max = 0.0;  // the shader's c_r against the CPU's, same pixels
};

// Measures at every focal depth of `focal_depths` (one render: depth does not
// depend on b; one output pass per b). A 16-bit focus projector.
[[nodiscard]] Result<Precision> measure_precision(const PairSetup& setup, const ExactDepth& exact,
                                                  render::DepthFormat format, double frustum_near, double frustum_far,
                                                  std::span<const double> focal_depths);

}  // namespace optique::bench::dof
