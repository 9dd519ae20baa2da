#include "oblique_depth_experiment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "scene/state.h"

namespace optique::bench::oblique_depth {
namespace {

constexpr double kStep = 1.0 / 16777216.0;  // 2⁻²⁴: one step of a 24-bit depth buffer
constexpr double kDegree = std::numbers::pi / 180.0;

const std::array<glm::vec3, kObjectCount> kColours{glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f),
                                                   glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f),
                                                   glm::vec3(1.0f, 1.0f, 0.0f)};

struct Frame {
  glm::dvec3 origin;
  glm::dvec3 right;
  glm::dvec3 up;
  glm::dvec3 normal;
  [[nodiscard]] glm::dvec3 world(const glm::dvec2& s) const { return origin + right * s.x + up * s.y; }
};

Frame frame_of(const config::Screen& screen) {
  return {screen.origin, screen.right, screen.up, glm::normalize(glm::cross(screen.right, screen.up))};
}

glm::dvec2 screen_centre(const config::Screen& screen) { return {0.5 * screen.width, 0.5 * screen.height}; }

// The world point the eye sees through wall point `offset` (metres from the
// wall's centre) at `behind` metres behind the wall.
glm::dvec3 seen_at(const Installation& inst, const glm::dvec2& offset, double behind) {
  const Frame f = frame_of(inst.screen);
  const glm::dvec3 on_wall = f.world(screen_centre(inst.screen) + offset);
  const double eye_distance = glm::dot(inst.eye - f.origin, f.normal);
  return inst.eye + (on_wall - inst.eye) * ((eye_distance + behind) / eye_distance);
}

struct Plane {
  glm::dvec3 normal;  // unit, towards the eye
  double offset;      // normal · x = offset
};

Plane plane_through(const Installation& inst, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  if (glm::dot(inst.eye - a, n) < 0.0) n = -n;
  return {n, glm::dot(n, a)};
}

// Where the eye's ray through wall point `offset` meets `plane`.
glm::dvec3 on_plane(const Installation& inst, const Plane& plane, const glm::dvec2& offset) {
  const glm::dvec3 through = seen_at(inst, offset, 0.0);
  const glm::dvec3 d = through - inst.eye;
  const double t = (plane.offset - glm::dot(plane.normal, inst.eye)) / glm::dot(plane.normal, d);
  return inst.eye + d * t;
}

// A quad as both sides see it: the renderer gets float vertices relative to
// the centroid and the centroid as a (double) model translation; the CPU
// traces those same float vertices in double, so the two start from the same
// geometry and differ only by the renderer's float arithmetic after it.
struct Quad {
  Object id = kBackground;
  glm::dvec3 centroid{0.0};
  std::array<glm::vec3, 4> local{};
  std::array<glm::dvec3, 4> corners{};  // centroid + local, in double
};

Quad make_quad(Object id, const std::array<glm::dvec3, 4>& corners) {
  Quad q;
  q.id = id;
  for (const auto& c : corners) q.centroid += c * 0.25;
  for (std::size_t i = 0; i < 4; ++i) {
    q.local[i] = glm::vec3(corners[i] - q.centroid);
    q.corners[i] = q.centroid + glm::dvec3(q.local[i]);
  }
  return q;
}

Quad quad_on(const Installation& inst, Object id, const Plane& plane, const glm::dvec2& lo, const glm::dvec2& hi) {
  return make_quad(id, {on_plane(inst, plane, lo), on_plane(inst, plane, {hi.x, lo.y}), on_plane(inst, plane, hi),
                        on_plane(inst, plane, {lo.x, hi.y})});
}

// The four objects, in drawing order. The layers cover the left part of the
// wall; the back one reaches beyond the front one on every side, so the front
// one's outline is a real visibility boundary. The crossing pair covers the
// right part: the depth difference between them is ±6 cm over half a metre, a
// shallow angle, so any depth that is not affine per triangle in window space
// would move their intersection line visibly.
std::array<Quad, 4> layer_quads(const Installation& inst, double delta) {
  const Plane back = plane_through(inst, seen_at(inst, {-0.95, -0.6}, 1.0), seen_at(inst, {0.35, -0.6}, 3.0),
                                   seen_at(inst, {-0.95, 0.6}, 1.4));
  const Plane front{back.normal, back.offset + delta};
  const Plane cross_a = plane_through(inst, seen_at(inst, {0.5, -0.6}, 1.8), seen_at(inst, {1.0, -0.6}, 2.2),
                                      seen_at(inst, {0.5, 0.6}, 2.0));
  const Plane cross_b = plane_through(inst, seen_at(inst, {0.5, -0.6}, 1.86), seen_at(inst, {1.0, -0.6}, 2.14),
                                      seen_at(inst, {0.5, 0.6}, 1.94));
  return {quad_on(inst, kBack, back, {-1.05, -0.65}, {0.45, 0.65}),
          quad_on(inst, kFront, front, {-0.95, -0.5}, {0.35, 0.5}),
          quad_on(inst, kCrossA, cross_a, {0.5, -0.65}, {1.05, 0.65}),
          quad_on(inst, kCrossB, cross_b, {0.5, -0.65}, {1.05, 0.65})};
}

// Ray parameter where origin + t·d meets triangle abc (Möller–Trumbore), or +∞.
double hit_triangle(const glm::dvec3& origin, const glm::dvec3& d, const glm::dvec3& a, const glm::dvec3& b,
                    const glm::dvec3& c) {
  constexpr double kMiss = std::numeric_limits<double>::infinity();
  const glm::dvec3 e1 = b - a;
  const glm::dvec3 e2 = c - a;
  const glm::dvec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-18) return kMiss;
  const glm::dvec3 s = origin - a;
  const double u = glm::dot(s, p) / det;
  if (u < 0.0 || u > 1.0) return kMiss;
  const glm::dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) / det;
  if (v < 0.0 || u + v > 1.0) return kMiss;
  const double t = glm::dot(e2, q) / det;
  return t > 0.0 ? t : kMiss;
}

double hit_quad(const glm::dvec3& origin, const glm::dvec3& d, const Quad& q) {
  const auto& c = q.corners;  // the renderer's triangles: 0 1 2 and 0 2 3
  return std::min(hit_triangle(origin, d, c[0], c[1], c[2]), hit_triangle(origin, d, c[0], c[2], c[3]));
}

// The exact answer at one sample: the nearest object, and for the gap the
// eye-space depths (along the wall's normal) of the back and front layers.
struct Sample {
  int id = kBackground;
  double back_depth = 0.0;
  double front_depth = 0.0;
};

Sample trace(const Installation& inst, const Frame& frame, const std::array<Quad, 4>& quads, const glm::dvec2& s) {
  Sample sample;
  const glm::dvec3 d = frame.world(s) - inst.eye;
  double nearest = std::numeric_limits<double>::infinity();
  for (const Quad& q : quads) {
    const double t = hit_quad(inst.eye, d, q);
    if (!std::isfinite(t)) continue;
    const double depth = -glm::dot(d * t, frame.normal);
    if (q.id == kBack) sample.back_depth = depth;
    if (q.id == kFront) sample.front_depth = depth;
    if (t < nearest) {
      nearest = t;
      sample.id = q.id;
    }
  }
  return sample;
}

glm::dvec2 apply(const glm::dmat3& m, const glm::dvec2& p) {
  const glm::dvec3 q = m * glm::dvec3(p, 1.0);
  return glm::dvec2(q) / q.z;
}

// A pinhole projector: where it is and which way it looks.
struct Pinhole {
  glm::dvec3 position;  // screen frame (z towards the viewer)
  glm::dmat3 rotation;  // screen frame → camera (x right, y down, z forward), glm column-major
};

Pinhole pinhole(const config::Screen& screen, const Placement& p) {
  const glm::dvec3 centre(screen_centre(screen), 0.0);
  const double theta = p.incidence_deg * kDegree;
  const double psi = p.azimuth_deg * kDegree;
  const glm::dvec3 direction(std::sin(theta) * std::cos(psi), std::sin(theta) * std::sin(psi), std::cos(theta));
  Pinhole ph;
  ph.position = centre + direction * p.distance;
  const glm::dvec3 forward = glm::normalize(centre - ph.position);
  // Image rows stay as level as the aim allows: x from the wall's up, y down.
  const glm::dvec3 level_x = glm::normalize(glm::cross(forward, glm::dvec3(0.0, 1.0, 0.0)));
  const glm::dvec3 level_y = glm::cross(forward, level_x);
  const double roll = p.roll_deg * kDegree;
  const glm::dvec3 x = level_x * std::cos(roll) + level_y * std::sin(roll);
  const glm::dvec3 y = level_y * std::cos(roll) - level_x * std::sin(roll);
  ph.rotation = glm::transpose(glm::dmat3(x, y, forward));  // rows x, y, forward
  return ph;
}

glm::dmat3 homography_of(const Pinhole& ph, const Placement& p, double ratio) {
  glm::dmat3 k(0.0);
  const double focal = ratio * p.width;
  k[0][0] = focal;
  k[1][1] = focal;
  k[2][0] = 0.5 * p.width;
  k[2][1] = 0.5 * p.height;
  k[2][2] = 1.0;
  // Screen point (x, y, 0) in camera space is x·R₁ + y·R₂ − R·position.
  const glm::dmat3 rt(ph.rotation[0], ph.rotation[1], -(ph.rotation * ph.position));
  return k * rt;
}

// Length on the wall of the image's middle row for throw ratio `ratio`, or +∞
// when some image corner misses the wall plane (the image reaches the horizon).
double middle_row_length(const Pinhole& ph, const Placement& p, double ratio) {
  const glm::dmat3 h = homography_of(ph, p, ratio);
  const glm::dmat3 inverse = glm::inverse(h);
  // The plane is in front of the camera where H⁻¹'s w has the sign it has at the
  // image centre; a corner with the other sign lies beyond the horizon.
  const double centre_w = (inverse * glm::dvec3(0.5 * p.width, 0.5 * p.height, 1.0)).z;
  for (const glm::dvec2 corner :
       {glm::dvec2(0, 0), glm::dvec2(p.width, 0), glm::dvec2(p.width, p.height), glm::dvec2(0, p.height)}) {
    if ((inverse * glm::dvec3(corner, 1.0)).z * centre_w <= 0.0) return std::numeric_limits<double>::infinity();
  }
  const glm::dvec2 left = apply(inverse, {0.0, 0.5 * p.height});
  const glm::dvec2 right = apply(inverse, {static_cast<double>(p.width), 0.5 * p.height});
  return glm::length(right - left);
}

double window_z(const Installation& inst, double eye_depth, double scale, double w) {
  const double n = inst.near;
  const double f = inst.far;
  const double ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * eye_depth);
  return 0.5 + 0.5 * scale * ndc / w;
}

// The depth row and A a method draws with (aligned: none).
struct DepthModel {
  bool oblique = true;
  glm::dmat3 a{1.0};
  double scale = 1.0;
};

DepthModel depth_model(const Projector& p, Method method) {
  const glm::dmat3& ours = p.view.oblique().user_to_projector;
  switch (method) {
    case Method::ours:
      return {true, ours, p.k};
    case Method::paper:
      return {true, p.paper_a, p.paper_factor};
    case Method::aligned:
      return {false, glm::dmat3(1.0), 1.0};
    case Method::naive:
      return {true, ours, 1.0};
    case Method::negated:
      return {true, ours, -p.k};
  }
  return {};
}

int classify(const image::FloatImage& image, int x, int y) {
  int best = kBackground;
  float best_distance = std::numeric_limits<float>::infinity();
  for (int id = 0; id < kObjectCount; ++id) {
    float distance = 0.0f;
    for (int c = 0; c < 3; ++c) {
      const float e = image.at(x, y, c) - kColours[static_cast<std::size_t>(id)][c];
      distance += e * e;
    }
    if (distance < best_distance) {
      best_distance = distance;
      best = id;
    }
  }
  return best;
}

}  // namespace

Installation installation() {
  Installation inst;
  inst.screen.id = "wall";
  inst.screen.origin = {-1.0, 0.9, 0.0};
  inst.screen.right = {1.0, 0.0, 0.0};
  inst.screen.up = {0.0, 1.0, 0.0};
  inst.screen.width = 2.0;
  inst.screen.height = 1.2;
  inst.eye = {0.0, 1.5, 2.0};
  return inst;
}

Result<Projector> make_projector(const Installation& inst, const Placement& placement) {
  const Pinhole ph = pinhole(inst.screen, placement);
  // The middle row's length falls as the throw ratio grows: bisect in log space.
  double lo = std::log(0.05);
  double hi = std::log(500.0);
  if (!(middle_row_length(ph, placement, std::exp(hi)) < placement.lit_width)) {
    return Error{"no throw ratio lights only " + std::to_string(placement.lit_width) + " m"};
  }
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (middle_row_length(ph, placement, std::exp(mid)) > placement.lit_width ? lo : hi) = mid;
  }
  const glm::dmat3 h = homography_of(ph, placement, std::exp(hi));
  auto geometry = geometry::ProjectorGeometry::make(h, placement.width, placement.height);
  if (!geometry) return Error{geometry.error()};
  auto view = render::ProjectorView::make(inst.screen, geometry.value(), render::RenderMethod::single_pass);
  if (!view) return Error{view.error()};
  Projector p(std::move(view).value());
  p.placement = placement;
  p.throw_ratio = std::exp(hi);
  p.screen_to_pixel = h;
  const geometry::ObliqueProjection& oblique = p.view.oblique();
  p.k = oblique.depth_scale;
  // Eq. 5 needs a33 = 1; a33 is w at R's centre, positive for the lit quad's own
  // sign of w unless R's centre is at or beyond the projector's horizon.
  const double a33 = oblique.user_to_projector[2][2];
  if (!(a33 > 1e-12)) return Error{"a33 ≤ 0: R's centre is beyond the projector's horizon, eq. 5 is undefined"};
  p.paper_a = oblique.user_to_projector / a33;
  p.paper_factor = 1.0 - std::abs(p.paper_a[0][2]) - std::abs(p.paper_a[1][2]);
  // Compression at the worst pixel inside R, over the pixel centres.
  p.ours_compression = std::numeric_limits<double>::infinity();
  p.paper_compression = std::numeric_limits<double>::infinity();
  for (int y = 0; y < placement.height; ++y) {
    for (int x = 0; x < placement.width; ++x) {
      const glm::dvec2 s = geometry.value().to_screen({x + 0.5, y + 0.5});
      if (!oblique.bounds.contains(s)) continue;
      const glm::dvec2 u = oblique.user_ndc(s);
      const double w_ours = (oblique.user_to_projector * glm::dvec3(u, 1.0)).z;
      const double w_paper = (p.paper_a * glm::dvec3(u, 1.0)).z;
      p.ours_compression = std::min(p.ours_compression, p.k / w_ours);
      p.paper_compression = std::min(p.paper_compression, p.paper_factor / w_paper);
    }
  }
  return p;
}

scene::SceneDefinition layer_scene(const Installation& inst, double delta) {
  scene::SceneDefinition scene;
  scene.name = "thin layers";
  scene.ambient = glm::vec3(0.0f);
  scene.background = kColours[kBackground];
  for (const Quad& q : layer_quads(inst, delta)) {
    scene::Mesh mesh;
    mesh.name = "quad " + std::to_string(q.id);
    for (const glm::vec3& v : q.local) mesh.vertices.push_back({v, glm::vec3(0.0f, 0.0f, 1.0f), glm::vec2(0.0f)});
    mesh.indices = {0, 1, 2, 0, 2, 3};
    const auto index = static_cast<std::uint32_t>(scene.meshes.size());
    scene.meshes.push_back(std::move(mesh));
    // Only the emissive term is drawn (no lights, no ambient): the colour is the id.
    scene.materials.emplace_back(glm::vec3(0.0f), 0.0f, 1.0f, kColours[static_cast<std::size_t>(q.id)]);
    scene::Instance instance;
    instance.mesh = index;
    instance.material = index;
    instance.transform = glm::translate(glm::dmat4(1.0), q.centroid);
    scene.instances.push_back(instance);
  }
  return scene;
}

Result<Count> Experiment::measure(const Projector& projector, double delta, Method method, render::DepthFormat format) {
  const int width = projector.placement.width;
  const int height = projector.placement.height;
  auto& renderer = renderers_[{delta, static_cast<int>(format)}];
  if (!renderer || renderer->output().width() != width || renderer->output().height() != height) {
    auto created = render::SceneRenderer::create(layer_scene(inst_, delta), width, height, format);
    if (!created) return Error{created.error()};
    renderer = std::move(created).value();
  }

  const render::ProjectorView& view = projector.view;
  const geometry::ObliqueProjection& ours = view.oblique();
  const DepthModel model = depth_model(projector, method);
  // Ours goes through ProjectorView itself, so the test checks what nodes draw.
  auto frustum = method == Method::ours ? view.frustum(inst_.eye, inst_.near, inst_.far)
                                        : geometry::off_axis_frustum(view.bounds(), inst_.eye, inst_.near, inst_.far);
  if (!frustum) return Error{frustum.error()};
  if (model.oblique && method != Method::ours) {
    const geometry::ObliqueProjection drawn{ours.bounds, model.a, model.scale};
    frustum.value().projection = drawn.matrix() * frustum.value().projection;
  }
  renderer->draw(scene::SceneState{}, {0.0, inst_.eye, frustum.value()});
  const image::FloatImage image = renderer->read_rendered();  // top row first, as projector pixels

  // The wall point of a pixel centre (x, y may be one outside the image).
  const glm::dmat3 pixel_to_screen = glm::inverse(projector.screen_to_pixel);
  const geometry::ScreenRect& r = ours.bounds;
  auto wall_point = [&](int x, int y) {
    const glm::dvec2 centre(x + 0.5, y + 0.5);
    if (model.oblique) return apply(pixel_to_screen, centre);
    return glm::dvec2(r.min.x + centre.x / width * r.width(), r.max.y - centre.y / height * r.height());
  };

  // Exact answers on a grid one pixel wider on every side, for the neighbours.
  const Frame frame = frame_of(inst_.screen);
  const auto quads = layer_quads(inst_, delta);
  const int gw = width + 2;
  const int gh = height + 2;
  std::vector<Sample> grid(static_cast<std::size_t>(gw) * gh);
  for (int y = -1; y <= height; ++y) {
    for (int x = -1; x <= width; ++x) {
      // Beyond R (off the wall) the single pass still draws, since only the
      // projector's own frustum clips; those pixels are masked and not counted
      // below, but they are traced so their neighbours inside see no false edge.
      grid[static_cast<std::size_t>(y + 1) * gw + (x + 1)] = trace(inst_, frame, quads, wall_point(x, y));
    }
  }

  Count count;
  count.min_gap_steps = std::numeric_limits<double>::infinity();
  verdicts_.assign(static_cast<std::size_t>(width) * height, 0);
  truth_.assign(static_cast<std::size_t>(width) * height, kBackground);
  gaps_.assign(static_cast<std::size_t>(width) * height, std::numeric_limits<float>::quiet_NaN());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Sample& centre = grid[static_cast<std::size_t>(y + 1) * gw + (x + 1)];
      const auto at = static_cast<std::size_t>(y) * width + x;
      truth_[at] = centre.id;
      if (!r.contains(wall_point(x, y))) {
        ++count.masked;
        verdicts_[at] = 3;
        continue;
      }
      bool boundary = false;
      for (int dy = -1; dy <= 1 && !boundary; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (grid[static_cast<std::size_t>(y + 1 + dy) * gw + (x + 1 + dx)].id != centre.id) boundary = true;
        }
      }
      if (boundary) {
        ++count.excluded;
        verdicts_[at] = 1;
        continue;
      }
      ++count.counted;
      if (classify(image, x, y) != centre.id) {
        ++count.errors;
        verdicts_[at] = 2;
      }
      if (centre.id == kFront) {
        ++count.front_pixels;
        double w = 1.0;
        if (model.oblique) w = (model.a * glm::dvec3(ours.user_ndc(wall_point(x, y)), 1.0)).z;
        const double gap =
            (window_z(inst_, centre.back_depth, model.scale, w) - window_z(inst_, centre.front_depth, model.scale, w)) /
            kStep;
        count.min_gap_steps = std::min(count.min_gap_steps, gap);
        if (gap < 2.0) ++count.under_two_steps;
        gaps_[at] = static_cast<float>(gap);
      }
    }
  }
  if (count.front_pixels == 0) count.min_gap_steps = 0.0;
  return count;
}

}  // namespace optique::bench::oblique_depth
