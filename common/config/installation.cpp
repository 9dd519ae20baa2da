#include "config/installation.h"

#include <algorithm>
#include <cassert>

#include "config/names.h"
#include "scene/scripted_path.h"

namespace optique::config {

std::string_view to_string(Eye eye) { return name_of(kEyeNames, eye); }
std::string_view to_string(RenderMethod method) { return name_of(kRenderMethodNames, method); }
std::string_view to_string(ContentRole role) { return name_of(kContentRoleNames, role); }
std::string_view to_string(StragglerPolicy policy) { return name_of(kStragglerPolicyNames, policy); }
std::string_view to_string(OutputKind kind) { return name_of(kOutputKindNames, kind); }

geometry::WorldRect Screen::world(const geometry::ScreenRect& part) const {
  geometry::WorldRect rect;
  rect.right = right;
  rect.up = up;
  rect.lower_left = point(part.min);
  rect.width = part.width();
  rect.height = part.height();
  return rect;
}

geometry::ProjectorGeometry Projector::geometry() const {
  auto made = geometry::ProjectorGeometry::make(homography, width, height);
  assert(made);  // checked when the installation was parsed
  return std::move(made).value();
}

glm::dvec3 Viewer::eye_at(double seconds) const {
  assert(!path.empty());
  return scene::path_value(path, seconds, [](const PathPoint& p) { return p.position; });
}

glm::dvec3 Viewer::eye_in(const scene::SceneState& state, double fraction, Eye eye) const {
  return geometry::eye_position(scene::eyes_at(state, fraction), scene::head_at(state, fraction) * head_right,
                                eye_separation, eye);
}

glm::dvec2 Gaze::at(double seconds) const {
  assert(!path.empty());
  return scene::path_value(path, seconds, [](const GazePoint& p) { return p.point; });
}

std::optional<std::size_t> Installation::find_projector(std::string_view id) const {
  const auto found = std::find_if(projectors.begin(), projectors.end(), [&](const Projector& p) { return p.id == id; });
  if (found == projectors.end()) return std::nullopt;
  return static_cast<std::size_t>(found - projectors.begin());
}

}  // namespace optique::config
