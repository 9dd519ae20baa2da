// The viewer: where the eyes are (a point, a path, or a tracked head) and the
// depth range of the view.
#include <cmath>

#include <glm/geometric.hpp>

#include "config/asset_path.h"
#include "config/navigation.h"
#include "config/sections.h"
#include "config/tracking.h"
#include "util/number_text.h"

namespace optique::config {

Viewer parse_viewer(const schema::Viewer& v, const std::string& config_dir, Checker& check) {
  using util::number_text;
  Viewer viewer;
  const bool has_eye = !v.eye().empty();
  const bool has_path = !v.path().empty();
  if (has_eye == has_path) {
    check.fail("viewer",
               has_eye ? "give either eye or path, not both" : "give the eye position: eye [x, y, z] or a path");
  }
  if (has_eye) {
    if (const auto eye = check.vec3("viewer.eye", v.eye()); eye && !has_path) viewer.path.push_back({0.0, *eye});
  }
  for (int i = 0; i < v.path_size(); ++i) {
    const std::string at = "viewer.path[" + std::to_string(i) + "]";
    check.non_negative(at + ".time", v.path(i).time());
    const auto position = check.vec3(at + ".position", v.path(i).position());
    if (i > 0) check.later(at + ".time", v.path(i).time(), v.path(i - 1).time());
    if (position) viewer.path.push_back({v.path(i).time(), *position});
  }
  check.non_negative("viewer.eye_separation", v.eye_separation());
  check.non_negative("viewer.near", v.near());
  check.non_negative("viewer.far", v.far());
  viewer.eye_separation = v.eye_separation() != 0.0 ? v.eye_separation() : defaults::kEyeSeparation;
  viewer.near = v.near() != 0.0 ? v.near() : defaults::kNear;
  viewer.far = v.far() != 0.0 ? v.far() : defaults::kFar;
  if (std::isfinite(viewer.near) && std::isfinite(viewer.far) && viewer.near >= 0.0 && viewer.far >= 0.0 &&
      !(viewer.far > viewer.near)) {
    check.fail("viewer.far",
               "must be greater than near (" + number_text(viewer.far) + " m <= " + number_text(viewer.near) + " m)");
  }
  if (!v.head_right().empty()) {
    if (const auto right = check.vec3("viewer.head_right", v.head_right());
        right && check.unit("viewer.head_right", *right)) {
      viewer.head_right = glm::normalize(*right);
    }
  }
  if (v.eye_separation() > 1.0) {
    check.fail("viewer.eye_separation",
               "is in metres; " + number_text(v.eye_separation()) + " m is not an eye separation");
  }
  if (v.has_tracking()) {
    viewer.tracking = parse_tracking(v.tracking(), "viewer.tracking", check.problems());
    if (!viewer.tracking->file.empty()) viewer.tracking->file = resolve_asset(viewer.tracking->file, config_dir);
  }
  if (v.has_navigation()) {
    const Navigation navigation = parse_navigation(v.navigation(), "viewer.navigation", check.problems());
    if (navigation.mode == NavigationMode::flystick) {
      if (!viewer.tracking || viewer.tracking->source != TrackingSource::dtrack) {
        check.fail("viewer.navigation.mode",
                   "flystick needs viewer.tracking with source dtrack: the flystick's lines come from DTrack");
      }
      viewer.navigation = navigation;
    }
  }
  return viewer;
}

}  // namespace optique::config
