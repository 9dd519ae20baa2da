#pragma once
// Depth order of the single-pass oblique projection, measured (docs/design.md,
// "Raskar: oblique projector", Depth): a synthetic wall, a viewer, a pinhole
// projector at growing incidence, and thin layers behind the wall. Each
// rendered pixel's object (read back as its emissive colour) is compared with
// exact visibility, ray-traced on the CPU in double precision. Shared by the
// benchmark (optique-bench-oblique-depth, the full sweep and the report) and
// the gpu test (the facts that must hold).

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "config/installation.h"
#include "geometry/projector_geometry.h"
#include "render/projector_view.h"
#include "render/scene_renderer.h"
#include "scene/definition.h"
#include "util/result.h"

namespace optique::bench::oblique_depth {

// The installation: a 2 m × 1.2 m wall in the world plane z = 0 with its
// lower-left corner at (−1, 0.9, 0), so world and screen frame differ by an
// offset; the viewer's eye 2 m in front of the wall's centre.
struct Installation {
  config::Screen screen;
  glm::dvec3 eye{0.0};
  double near = 0.1;  // the clip planes every frustum uses (a common default)
  double far = 100.0;
};
[[nodiscard]] Installation installation();

// A projector aimed at the wall's centre from `distance` metres away, its axis
// at `incidence_deg` from the wall's normal, leaning towards `azimuth_deg`
// (0: to the right, a yaw about the wall's vertical; 90: above, a pitch; 45: a
// diagonal, both at once). Square pixels; the throw ratio is chosen so that
// the image's middle row spans `lit_width` metres of wall, so every incidence
// lights about the same stretch of wall and only the obliqueness changes.
// `roll_deg` turns the image about the projector's axis (a projector mounted
// askew): its lit quad then no longer fills its bounding rectangle R.
struct Placement {
  std::string series;
  double incidence_deg = 0.0;
  double azimuth_deg = 0.0;
  double roll_deg = 0.0;
  double distance = 2.5;
  double lit_width = 1.6;
  int width = 640;
  int height = 400;
};

// Everything one placement fixes: the homography, the single-pass projection
// the renderer uses (ours), and the paper's eq. 5 version of the same A.
struct Projector {
  explicit Projector(render::ProjectorView view_) : view(std::move(view_)) {}
  Placement placement;
  double throw_ratio = 0.0;
  glm::dmat3 screen_to_pixel{1.0};  // H
  render::ProjectorView view;
  // Ours: A normalized so that w ∈ [k, 1] over the lit quad within the wall, third row k.
  double k = 0.0;
  // Eq. 5: A with a33 = 1, third row 1 − |a31| − |a32| (≤ 0: the method has no
  // valid depth for this projector).
  glm::dmat3 paper_a{1.0};
  double paper_factor = 0.0;
  // The smallest depth_scale / w over the projector's pixels inside R: how much
  // the depth differences of the viewer's frustum shrink at the worst pixel.
  double ours_compression = 0.0;
  double paper_compression = 0.0;
};
[[nodiscard]] Result<Projector> make_projector(const Installation& inst, const Placement& placement);

// How a frame is drawn.
enum class Method {
  ours,     // ProjectorView's single pass: A′ · P_U
  paper,    // the same A with eq. 5's depth row
  aligned,  // the viewer's own frustum through R, no A: the depth buffer's own limit
  naive,    // A with the third row [0 0 1 0]: a deliberately wrong depth row (clips)
  negated,  // A with the third row [0 0 −k 0]: a deliberately wrong depth row (reverses order)
};

// One frame's verdict. Pixels whose exact answer changes within one pixel of
// their centre (silhouettes, the intersection line, R's edge) are excluded:
// there the rasterizer's sampling decides, not depth.
struct Count {
  int counted = 0;
  int excluded = 0;
  int masked = 0;              // pixels off the wall (outside R): the projector shows black there
  int errors = 0;              // counted pixels showing another object than the exact answer
  int front_pixels = 0;        // counted pixels where the front layer is the exact answer
  double min_gap_steps = 0.0;  // smallest window-z gap front → back over those, in 2⁻²⁴ steps
  int under_two_steps = 0;     // of those, how many have a gap under two steps
};

// The thin-layer scene for a separation `delta` (metres), each object one
// emissive colour: a back and a front layer (parallel, `delta` apart, tilted
// so that they run from 1 m to 3 m behind the wall, the back one drawn first
// so a depth tie shows the wrong one), and two quads crossing at a shallow
// angle about 2 m behind the wall.
[[nodiscard]] scene::SceneDefinition layer_scene(const Installation& inst, double delta);

// Renders and counts; keeps one renderer per (delta, depth format) for reuse.
// Needs a current GL context.
class Experiment {
 public:
  explicit Experiment(Installation inst) : inst_(std::move(inst)) {}
  [[nodiscard]] const Installation& installation() const { return inst_; }

  [[nodiscard]] Result<Count> measure(const Projector& projector, double delta, Method method,
                                      render::DepthFormat format);
  // The last measured frame: 0 counted and right, 1 excluded, 2 error, 3 masked;
  // one byte per pixel, top row first (for error maps).
  [[nodiscard]] const std::vector<unsigned char>& last_verdicts() const { return verdicts_; }
  [[nodiscard]] const std::vector<int>& last_truth() const { return truth_; }
  // Per pixel of the last frame: the exact window-z gap front → back in 2⁻²⁴
  // steps where the front layer is the counted answer, NaN elsewhere.
  [[nodiscard]] const std::vector<float>& last_gaps() const { return gaps_; }

 private:
  Installation inst_;
  std::map<std::pair<double, int>, std::unique_ptr<render::SceneRenderer>> renderers_;
  std::vector<unsigned char> verdicts_;
  std::vector<int> truth_;
  std::vector<float> gaps_;
};

// Object ids: what a pixel shows.
enum Object : int { kBackground = 0, kBack = 1, kFront = 2, kCrossA = 3, kCrossB = 4, kObjectCount = 5 };

}  // namespace optique::bench::oblique_depth
