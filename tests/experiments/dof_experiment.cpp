#include "dof_experiment.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include <glm/geometric.hpp>

#include "scene_load/installation_scene.h"
#include "config/load.h"
#include "config/parse.h"
#include "image/compare.h"
#include "image/texture_decode.h"
#include "scene_load/load_scene.h"
#include "scene/raycast.h"

namespace optique::bench::dof {
namespace {

constexpr double kStep24 = 1.0 / 16777216.0;  // 2⁻²⁴: one step of a 24-bit depth buffer
// Below this much light the read-back c_r = 1 − focus / I is dominated by the
// 16-bit signal's step, not by c_r.
constexpr double kLeastLight = 1e-3;

// One node of the pair (or a plain one for FocusRole::none, drawing the whole
// image), its pipeline built as its node builds it, with `bits` of signal and
// the viewer's frustum at `frustum_near` … `frustum_far`.
Result<std::unique_ptr<render::ProjectorPipeline>> make_node(const PairSetup& setup, render::FocusRole role, int bits,
                                                             render::DepthFormat format, double frustum_near,
                                                             double frustum_far) {
  config::ProjectorJob job = role == render::FocusRole::defocus ? setup.defocus : setup.focus;
  config::Projector& projector = job.installation.projectors[job.projector];
  projector.response.bits = bits;
  if (role == render::FocusRole::none) projector.content = {};
  job.installation.viewer.near = frustum_near;
  job.installation.viewer.far = frustum_far;
  return render::ProjectorPipeline::make(job, setup.scene, {.depth = format});
}

// c_r of an exact depth; a ray that meets nothing is as far as the range's far end.
double exact_coc(float depth, double b, const optics::CocRange& range) {
  return optics::relative_coc(std::isfinite(depth) ? static_cast<double>(depth) : range.far, b, range);
}

}  // namespace

Result<PairSetup> load_setup(const std::string& config_path, int divisor) {
  if (divisor < 1) return Error{"the divisor must be at least 1"};
  // Smaller projectors for quicker runs: divided before the config is parsed, so
  // that their geometry (a region) follows.
  std::ifstream file(config_path);
  std::ostringstream text;
  text << file.rdbuf();
  auto schema = config::read_schema(text.str(), config_path);
  if (!schema) return Error{schema.error()};
  for (schema::Projector& p : *schema.value().mutable_projectors()) {
    p.set_width(p.width() / static_cast<std::uint32_t>(divisor));
    p.set_height(p.height() / static_cast<std::uint32_t>(divisor));
  }
  const std::string directory = std::filesystem::path(config_path).parent_path().string();
  auto parsed = config::parse_installation(schema.value(), directory, config_path);
  if (!parsed) return Error{parsed.error()};
  const config::Installation& inst = parsed.value();
  PairSetup setup;
  std::optional<std::size_t> focus;
  std::optional<std::size_t> defocus;
  for (std::size_t i = 0; i < inst.projectors.size(); ++i) {
    const config::ContentRole role = inst.projectors[i].content.role;
    if (role == config::ContentRole::focus && !focus) focus = i;
    if (role == config::ContentRole::defocus && !defocus) defocus = i;
  }
  if (!focus || !defocus) return Error{config_path + ": needs a projector of role focus and one of defocus"};
  if (!inst.depth_of_field) return Error{config_path + ": has no depth_of_field"};
  setup.focus = config::job_for(inst, *focus);
  setup.defocus = config::job_for(inst, *defocus);
  auto scene = config::load_scene(inst, image::decode_texture);
  if (!scene) return Error{scene.error()};
  setup.scene = std::move(scene).value().definition;
  for (const auto& object : setup.scene.objects) {
    const scene::Pose pose = object.pose_at(0.0);
    setup.state.objects[object.id] = {pose, pose};
  }
  setup.eye = inst.viewer.eye_at(0.0);
  setup.state.eye_now = setup.state.eye_next = setup.eye;
  setup.frustum_near = inst.viewer.near;
  setup.frustum_far = inst.viewer.far;
  setup.range = {inst.depth_of_field->near, inst.depth_of_field->far};
  // blur_radius is in screen pixels; the pair's pixels may be finer or coarser.
  const config::Projector& defocused = setup.defocus.self();
  setup.c_max = defocused.content.blur_radius * defocused.geometry().max_pixels_per_metre() /
                setup.defocus.screen().pixels_per_metre;
  const glm::dvec3 normal = setup.focus.screen().world().normal();
  for (const auto& [id, object] : setup.state.objects) {
    setup.object_depths.push_back(glm::dot(setup.eye - object.now.position, normal));
  }
  std::sort(setup.object_depths.begin(), setup.object_depths.end());
  return setup;
}

std::vector<double> focal_sweep(const PairSetup& setup) {
  std::vector<double> sweep{setup.range.near, setup.range.far};
  for (double z : setup.object_depths) {
    if (z > setup.range.near && z < setup.range.far) sweep.push_back(z);
  }
  std::sort(sweep.begin(), sweep.end());
  // Between neighbours, halfway in 1/z (c_r is linear in 1/z), where they are far
  // enough apart for the point to be neither's focal plane.
  std::vector<double> between;
  for (std::size_t i = 0; i + 1 < sweep.size(); ++i) {
    if (sweep[i + 1] > 1.3 * sweep[i]) between.push_back(2.0 / (1.0 / sweep[i] + 1.0 / sweep[i + 1]));
  }
  sweep.insert(sweep.end(), between.begin(), between.end());
  std::sort(sweep.begin(), sweep.end());
  return sweep;
}

Result<ExactDepth> exact_depth(const PairSetup& setup) {
  const geometry::ProjectorGeometry geometry = setup.focus.self().geometry();
  const int width = geometry.width();
  const int height = geometry.height();
  const config::Screen& screen = setup.focus.screen();
  const glm::dvec3 normal = screen.world().normal();
  const scene::RayCaster caster(setup.scene, setup.state, 0.0);
  ExactDepth exact;
  exact.depth = image::FloatImage(width, height, 1);
  std::vector<int> seen(static_cast<std::size_t>(width) * height, -1);  // instance, −1: nothing
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::dvec3 through = screen.point(geometry.to_screen({x + 0.5, y + 0.5}));
      const auto hit = caster.cast({setup.eye, through - setup.eye});
      float& depth = exact.depth.at(x, y, 0);
      depth = std::numeric_limits<float>::infinity();
      if (hit) {
        depth = static_cast<float>(glm::dot(setup.eye - hit->point, normal));
        seen[static_cast<std::size_t>(y) * width + x] = static_cast<int>(hit->instance);
      }
    }
  }
  exact.silhouette.assign(seen.size(), 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const int centre = seen[static_cast<std::size_t>(y) * width + x];
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = std::clamp(x + dx, 0, width - 1);
          const int ny = std::clamp(y + dy, 0, height - 1);
          if (seen[static_cast<std::size_t>(ny) * width + nx] != centre) {
            exact.silhouette[static_cast<std::size_t>(y) * width + x] = 1;
          }
        }
      }
    }
  }
  return exact;
}

double psnr_against(const image::FloatImage& image, const FocalFrame& frame, bool away) {
  return image::psnr_luma_where(image, frame.ideal,
                                [&](int x, int y) { return !away || frame.coc.at(x, y, 0) > kAwayFromFocus; });
}

Result<std::unique_ptr<Pair>> Pair::create(const PairSetup& setup, int bits, render::DepthFormat depth) {
  std::unique_ptr<Pair> pair(new Pair(setup));
  for (auto [role, slot] :
       {std::pair{render::FocusRole::none, &pair->plain_}, std::pair{render::FocusRole::focus, &pair->focus_},
        std::pair{render::FocusRole::defocus, &pair->defocus_}}) {
    auto node = make_node(setup, role, bits, depth, setup.frustum_near, setup.frustum_far);
    if (!node) return Error{node.error()};
    *slot = std::move(node).value();
  }
  return pair;
}

optics::CocFromWindowDepth Pair::mapping(double b) const {
  return optics::coc_from_window_depth(b, setup_.range, setup_.frustum_near, setup_.frustum_far);
}

namespace {

// The pair's frames are always drawable: the eye is in front of the screen.
void draw(render::ProjectorPipeline& node, const scene::SceneState& state) {
  [[maybe_unused]] const auto drawn = node.draw(state);
  assert(drawn);
}

}  // namespace

void Pair::draw_plain() { draw(*plain_, setup_.state); }

void Pair::draw_focus(double b) {
  focus_->set_focus({b, {}});
  draw(*focus_, setup_.state);
}

void Pair::draw_defocus(double b) {
  defocus_->set_focus({b, {}});
  draw(*defocus_, setup_.state);
}

Result<FocalFrame> Pair::frame(double b, const ExactDepth& exact) {
  FocalFrame f;
  f.focal_depth = b;
  draw_plain();
  f.rendered = plain_->renderer().read_rendered();
  draw_focus(b);
  f.focus = focus_->renderer().output().read_linear();
  draw_defocus(b);
  f.defocus = defocus_->renderer().output().read_linear();
  if (exact.depth.width != f.rendered.width || exact.depth.height != f.rendered.height) {
    return Error{"the exact depth map is not the rendered image's size"};
  }

  // The screen: the focused light lands as it is, the defocused projector's
  // optics spread its light over its circle of confusion.
  f.composite = optics::disc_blur(f.defocus, setup_.c_max);
  for (std::size_t i = 0; i < f.composite.pixels.size(); ++i) {
    f.composite.pixels[i] = i % 4 == 3 ? 1.0f : f.composite.pixels[i] + f.focus.pixels[i];
  }

  f.coc = image::FloatImage(f.rendered.width, f.rendered.height, 1);
  image::FloatImage radius(f.rendered.width, f.rendered.height, 1);
  for (std::size_t i = 0; i < f.coc.pixels.size(); ++i) {
    const double c = exact_coc(exact.depth.pixels[i], b, setup_.range);
    f.coc.pixels[i] = static_cast<float>(c);
    radius.pixels[i] = static_cast<float>(c * setup_.c_max);
  }
  f.ideal = optics::scatter_defocus(f.rendered, radius);

  f.scores.pair = psnr_against(f.composite, f, false);
  f.scores.sharp = psnr_against(f.rendered, f, false);
  f.scores.pair_away = psnr_against(f.composite, f, true);
  f.scores.sharp_away = psnr_against(f.rendered, f, true);
  f.scores.away_pixels = static_cast<int>(
      std::count_if(f.coc.pixels.begin(), f.coc.pixels.end(), [](float c) { return c > kAwayFromFocus; }));
  return f;
}

Result<Precision> measure_precision(const PairSetup& setup, const ExactDepth& exact, render::DepthFormat format,
                                    double frustum_near, double frustum_far, std::span<const double> focal_depths) {
  auto node = make_node(setup, render::FocusRole::focus, 16, format, frustum_near, frustum_far);
  if (!node) return Error{node.error()};
  render::ProjectorPipeline& pipeline = *node.value();
  render::SceneRenderer& renderer = pipeline.renderer();

  Precision p;
  double buffer_sum = 0.0;
  double output_sum = 0.0;
  long buffer_samples = 0;
  image::FloatImage depth;
  image::FloatImage rendered;
  for (const double b : focal_depths) {
    const optics::CocFromWindowDepth mapping = optics::coc_from_window_depth(b, setup.range, frustum_near, frustum_far);
    pipeline.set_focus({b, {}});
    draw(pipeline, setup.state);
    if (depth.empty()) {
      depth = renderer.read_depth();
      rendered = renderer.read_rendered();
      if (depth.width != exact.depth.width || depth.height != exact.depth.height) {
        return Error{"the exact depth map is not the rendered image's size"};
      }
    }
    const image::FloatImage focus = renderer.output().read_linear();
    const bool first = b == focal_depths.front();
    for (int y = 0; y < depth.height; ++y) {
      for (int x = 0; x < depth.width; ++x) {
        if (exact.silhouette[static_cast<std::size_t>(y) * depth.width + x] != 0) {
          if (first) ++p.excluded;
          continue;
        }
        if (first) ++p.counted;
        const float z = exact.depth.at(x, y, 0);
        const float d = depth.at(x, y, 0);
        if (first && std::isfinite(z)) {
          const double steps = std::abs(d - optics::window_depth(z, frustum_near, frustum_far)) / kStep24;
          p.window_steps_max = std::max(p.window_steps_max, steps);
        }
        const double c_exact = exact_coc(z, b, setup.range);
        const double c_buffer = optics::relative_coc(d, mapping);
        const double e = std::abs(c_buffer - c_exact);
        p.buffer_max = std::max(p.buffer_max, e);
        buffer_sum += e;
        ++buffer_samples;
        // The channel with the most light says the most about the share.
        int channel = 0;
        for (int c = 1; c < 3; ++c) {
          if (rendered.at(x, y, c) > rendered.at(x, y, channel)) channel = c;
        }
        const double light = rendered.at(x, y, channel);
        if (light <= kLeastLight) continue;
        const double c_output = 1.0 - focus.at(x, y, channel) / light;
        const double o = std::abs(c_output - c_exact);
        ++p.output_counted;
        p.output_max = std::max(p.output_max, o);
        output_sum += o;
        p.output_vs_buffer_max = std::max(p.output_vs_buffer_max, std::abs(c_output - c_buffer));
      }
    }
  }
  p.buffer_mean = buffer_samples > 0 ? buffer_sum / static_cast<double>(buffer_samples) : 0.0;
  p.output_mean = p.output_counted > 0 ? output_sum / p.output_counted : 0.0;
  return p;
}

}  // namespace optique::bench::dof
