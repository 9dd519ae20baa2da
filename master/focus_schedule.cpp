#include "master/focus_schedule.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "scene/instance_tree.h"
#include "scene/raycast.h"
#include "scene/scripted_path.h"

namespace optique::master {

std::optional<FocusSchedule> FocusSchedule::make(const config::Installation& installation) {
  if (!installation.depth_of_field) return std::nullopt;
  FocusSchedule schedule;
  schedule.settings_ = *installation.depth_of_field;
  // Without a gaze (a fixed or scripted depth) no ray is cast and the frame is not needed.
  if (schedule.settings_.gaze) schedule.screen_ = installation.screens[schedule.settings_.gaze->screen];
  return schedule;
}

glm::dvec2 FocusSchedule::gaze_at(double seconds) const {
  return settings_.gaze ? settings_.gaze->at(seconds) : glm::dvec2(0.0);
}

protocol::Focus FocusSchedule::at(double seconds, const scene::SceneDefinition& scene, const scene::SceneState& state,
                                  const glm::dvec3& eye) const {
  protocol::Focus focus;
  const glm::dvec2 gaze = gaze_at(seconds);
  focus.gaze = gaze;
  double depth = settings_.far;
  if (settings_.focal_depth) {
    depth = *settings_.focal_depth;
  } else if (!settings_.focal_path.empty()) {
    depth = scene::path_value(settings_.focal_path, seconds, [](const config::FocusPoint& p) { return p.depth; });
  } else {
    // What the viewer looks at; nothing there: the far end of the depth of field.
    const glm::dvec3 target = screen_.point(gaze);
    const glm::dvec3 towards_viewer = glm::cross(screen_.right, screen_.up);
    // The ray goes through the world, where the navigation has carried the
    // installation; the hit comes back to measure its depth in the room.
    const glm::dmat4 to_world = scene::installation_to_world(state, 0.0);
    const glm::dvec3 from = glm::dvec3(to_world * glm::dvec4(eye, 1.0));
    const glm::dvec3 along = glm::dvec3(to_world * glm::dvec4(target - eye, 0.0));
    if (const auto hit = scene::cast_ray(scene, state, 0.0, {from, along})) {
      const glm::dvec3 in_room = glm::dvec3(glm::inverse(to_world) * glm::dvec4(hit->point, 1.0));
      depth = glm::dot(eye - in_room, towards_viewer);
    }
  }
  if (!std::isfinite(depth)) depth = settings_.far;
  focus.depth = std::clamp(depth, settings_.near, settings_.far);
  return focus;
}

}  // namespace optique::master
