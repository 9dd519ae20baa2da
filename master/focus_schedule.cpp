#include "master/focus_schedule.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "scene/raycast.h"
#include "scene/viewer_path.h"

namespace optique::master {

std::optional<FocusSchedule> FocusSchedule::make(const config::Installation& installation) {
  if (!installation.has_depth_of_field()) return std::nullopt;
  FocusSchedule schedule;
  schedule.settings_ = installation.depth_of_field();
  // The gaze's screen; without a gaze (a fixed or scripted depth) no ray is
  // cast and the frame is not needed.
  for (const config::Screen& s : installation.screens()) {
    if (s.id() != schedule.settings_.gaze().screen()) continue;
    schedule.origin_ = {s.origin(0), s.origin(1), s.origin(2)};
    schedule.right_ = {s.right(0), s.right(1), s.right(2)};
    schedule.up_ = {s.up(0), s.up(1), s.up(2)};
  }
  return schedule;
}

glm::dvec2 FocusSchedule::gaze_at(double seconds) const {
  const config::Gaze& gaze = settings_.gaze();
  if (!gaze.point().empty()) return {gaze.point(0), gaze.point(1)};
  if (gaze.path().empty()) return {0.0, 0.0};
  const scene::PathSpot spot = scene::path_spot(
      gaze.path_size(), [&](int i) { return gaze.path(i).time(); }, seconds);
  const auto point = [&](int i) { return glm::dvec2(gaze.path(i).point(0), gaze.path(i).point(1)); };
  return point(spot.from) * (1.0 - spot.fraction) + point(spot.to) * spot.fraction;
}

wire::Focus FocusSchedule::at(double seconds, const scene::SceneDefinition& scene, const scene::SceneState& state,
                              const glm::dvec3& eye) const {
  wire::Focus focus;
  const glm::dvec2 gaze = gaze_at(seconds);
  focus.set_gaze_x(gaze.x);
  focus.set_gaze_y(gaze.y);
  double depth = settings_.far();
  if (settings_.focal_depth() > 0.0) {
    depth = settings_.focal_depth();
  } else if (!settings_.focal_path().empty()) {
    const auto& path = settings_.focal_path();
    const scene::PathSpot spot = scene::path_spot(
        path.size(), [&](int i) { return path[i].time(); }, seconds);
    depth = settings_.focal_path(spot.from).depth() * (1.0 - spot.fraction) +
            settings_.focal_path(spot.to).depth() * spot.fraction;
  } else {
    // What the viewer looks at; nothing there: the far end of the depth of field.
    const glm::dvec3 target = origin_ + gaze.x * right_ + gaze.y * up_;
    const glm::dvec3 towards_viewer = glm::cross(right_, up_);
    if (const auto hit = scene::cast_ray(scene, state, 0.0, {eye, target - eye})) {
      depth = glm::dot(eye - hit->point, towards_viewer);
    }
  }
  if (!std::isfinite(depth)) depth = settings_.far();
  focus.set_depth(std::clamp(depth, settings_.near(), settings_.far()));
  return focus;
}

}  // namespace optique::master
