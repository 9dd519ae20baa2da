#include "scene_authority.h"

#include "scene/viewer_path.h"

namespace optique::master {

SceneAuthority::SceneAuthority(scene::SceneDefinition script, config::Viewer viewer, clock::Nanos frame_period)
    : script_(std::move(script)), viewer_(std::move(viewer)), period_(frame_period) {}

clock::Nanos SceneAuthority::simulation_time(std::uint64_t frame) const {
  return static_cast<clock::Nanos>(frame) * period_;
}

scene::SceneState SceneAuthority::state_at_frame(std::uint64_t frame) const {
  const double now = static_cast<double>(simulation_time(frame)) * 1e-9;
  const double next = static_cast<double>(simulation_time(frame + 1)) * 1e-9;
  scene::SceneState state;
  for (const auto& object : script_.objects) {
    state.objects.emplace(object.id, scene::ObjectState{object.pose_at(now), object.pose_at(next)});
  }
  state.eye_now = scene::eye_at(viewer_, now);
  state.eye_next = scene::eye_at(viewer_, next);
  return state;
}

}  // namespace optique::master
