#include "master/run/scene_authority.h"

namespace optique::master {

SceneAuthority::SceneAuthority(std::vector<scene::AnimatedObject> objects, config::Viewer viewer, double frame_rate,
                               LightSwitches switches)
    : objects_(std::move(objects)),
      viewer_(std::move(viewer)),
      switches_(std::move(switches)),
      period_(clock::frame_period(frame_rate)) {}

clock::Nanos SceneAuthority::simulation_time(std::uint64_t frame) const {
  return static_cast<clock::Nanos>(frame) * period_;
}

scene::SceneState SceneAuthority::state_at_frame(std::uint64_t frame) const {
  const double now = static_cast<double>(simulation_time(frame)) * 1e-9;
  const double next = static_cast<double>(simulation_time(frame + 1)) * 1e-9;
  scene::SceneState state;
  for (const auto& object : objects_) {
    state.objects.emplace(object.id, scene::ObjectState{object.pose_at(now), object.pose_at(next)});
  }
  state.eye_now = viewer_.eye_at(now);
  state.eye_next = viewer_.eye_at(next);
  state.lights_off = switches_.off_at(now);
  return state;
}

}  // namespace optique::master
