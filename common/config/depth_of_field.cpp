// Depth of field by optics: where the focal depth of each frame comes from (a
// depth, a path of depths, or the gaze on a screen) and its depth range.
#include <algorithm>
#include <cmath>

#include "config/sections.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

void depth_range(const schema::DepthOfField& d, Checker& check) {
  check.non_negative("depth_of_field.near", d.near());
  check.non_negative("depth_of_field.far", d.far());
  if (d.near() != 0.0 && d.far() != 0.0 && std::isfinite(d.near()) && std::isfinite(d.far()) && !(d.far() > d.near())) {
    check.fail("depth_of_field.far",
               "must be greater than near (" + number_text(d.far()) + " m <= " + number_text(d.near()) + " m)");
  }
  check.non_negative("depth_of_field.inset_radius", d.inset_radius());
}

// The gaze on its screen, each point on it.
std::optional<Gaze> gaze(const schema::Gaze& g, const std::vector<Screen>& screens, Scope scope, Checker& check) {
  const std::optional<std::size_t> index = find_screen(screens, g.screen());
  if (scope == Scope::job) {
    // A job does not carry the gaze's screen: its node has no use for the gaze.
    if (!index) return std::nullopt;
  } else {
    if (!index && every_screen_named(screens)) {
      check.fail("depth_of_field.gaze.screen", "unknown screen '" + g.screen() + "'");
    }
    if (g.point().empty() == g.path().empty()) {
      check.fail("depth_of_field.gaze", "give either point [x, y] or a path of points");
    }
  }
  const Screen* screen = index ? &screens[*index] : nullptr;
  const auto point = [&](const std::string& path,
                         const google::protobuf::RepeatedField<double>& p) -> std::optional<glm::dvec2> {
    if (p.size() != 2) {
      check.fail(path, "must be [x, y] in metres on the screen (got " + std::to_string(p.size()) + " numbers)");
      return std::nullopt;
    }
    if (!check.finite(path + "[0]", p[0]) || !check.finite(path + "[1]", p[1])) return std::nullopt;
    if (screen != nullptr && (p[0] < 0.0 || p[0] > screen->width || p[1] < 0.0 || p[1] > screen->height)) {
      check.fail(path, "[" + number_text(p[0]) + ", " + number_text(p[1]) + "] is off screen '" + screen->id + "' (" +
                           number_text(screen->width) + " × " + number_text(screen->height) + " m)");
    }
    return glm::dvec2(p[0], p[1]);
  };
  Gaze out;
  out.screen = index.value_or(0);
  if (!g.point().empty()) {
    if (const auto p = point("depth_of_field.gaze.point", g.point())) out.path.push_back({0.0, *p});
  }
  for (int i = 0; i < g.path_size(); ++i) {
    const std::string at = "depth_of_field.gaze.path[" + std::to_string(i) + "]";
    check.non_negative(at + ".time", g.path(i).time());
    const auto p = point(at + ".point", g.path(i).point());
    if (i > 0) check.later(at + ".time", g.path(i).time(), g.path(i - 1).time());
    if (p && g.point().empty()) out.path.push_back({g.path(i).time(), *p});
  }
  return out;
}

}  // namespace

bool needs_depth_of_field(const std::vector<Projector>& projectors) {
  return std::any_of(projectors.begin(), projectors.end(), [](const Projector& p) {
    return p.content.role == ContentRole::focus || p.content.role == ContentRole::defocus;
  });
}

std::optional<DepthOfField> parse_depth_of_field(const schema::Installation& installation,
                                                 const std::vector<Screen>& screens, const Viewer& viewer, Scope scope,
                                                 bool needed, Checker& check) {
  const schema::DepthOfField& d = installation.depth_of_field();
  if (scope == Scope::installation && needed) {
    const int sources = (d.focal_depth() != 0.0 ? 1 : 0) + (d.focal_path().empty() ? 0 : 1) + (d.has_gaze() ? 1 : 0);
    if (sources != 1) {
      check.fail("depth_of_field", sources == 0 ? "focus/defocus projectors need the focal depth: give focal_depth, "
                                                  "focal_path or gaze"
                                                : "give only one of focal_depth, focal_path and gaze");
    }
    if (d.focal_depth() != 0.0) check.positive("depth_of_field.focal_depth", d.focal_depth());
    for (int i = 0; i < d.focal_path_size(); ++i) {
      const std::string at = "depth_of_field.focal_path[" + std::to_string(i) + "]";
      check.non_negative(at + ".time", d.focal_path(i).time());
      check.positive(at + ".depth", d.focal_path(i).depth());
      if (i > 0) check.later(at + ".time", d.focal_path(i).time(), d.focal_path(i - 1).time());
    }
  }
  // A whole installation without a focus pair has no use for one
  // (check_across_sections says so when it is set).
  if (!installation.has_depth_of_field() || (scope == Scope::installation && !needed)) return std::nullopt;
  DepthOfField dof;
  if (d.focal_depth() != 0.0) dof.focal_depth = d.focal_depth();
  for (const schema::FocusPoint& point : d.focal_path()) dof.focal_path.push_back({point.time(), point.depth()});
  if (d.has_gaze()) dof.gaze = gaze(d.gaze(), screens, scope, check);
  depth_range(d, check);
  if (scope == Scope::installation && d.inset_radius() > 0.0 && !d.has_gaze()) {
    check.fail("depth_of_field.inset_radius", "the focused inset follows the gaze point: give gaze too");
  }
  dof.near = d.near() != 0.0 ? d.near() : viewer.near;
  dof.far = d.far() != 0.0 ? d.far() : viewer.far;
  dof.inset_radius = d.inset_radius();
  return dof;
}

}  // namespace optique::config
