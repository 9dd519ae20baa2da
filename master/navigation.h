#pragma once
// The viewer's travel through the world as the master moves it, without IO:
// the navigation (world ← installation) applications set, flown on by a
// flystick (viewer.navigation: the joystick forward along where the wand
// points, sideways turning about the world's vertical through the eyes) and
// brought back by its reset button to where applications last set it; each
// frame's navigation, now and a period later, into the frame's state. And the
// flysticks as applications hear of them: at most one FlystickChanged a
// flystick a frame, the newest as the frame begins.
//
// The flystick's flight is live input, as the head is: it is not journaled
// (--record keeps what applications set), so a replay travels only where they
// took it.

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "clock/clock.h"
#include "config/navigation.h"
#include "config/tracking.h"
#include "optique/session.pb.h"
#include "scene/state.h"
#include "tracking/dtrack_reader.h"
#include "tracking/head_tracker.h"

namespace optique::master {

// The flysticks remembered (DTrack numbers them from 0; a site has a few):
// others are ignored, so a flood of ids cannot grow the master.
inline constexpr std::size_t kMostFlysticks = 32;

// A joystick value with the dead zone taken out: 0 within it, then rising
// linearly to ±1 at the end of its travel.
[[nodiscard]] double beyond_dead_zone(double value, double dead_zone);

// `from` flown for `seconds` by a joystick at (`x`, `y`) (dead zone taken
// out): `y` along `pointing` (installation axes; none: the wand is not seen,
// and only turning goes on), `x` turning about `settings.up` through `eyes`
// (positive x turns the viewer to the right).
[[nodiscard]] scene::Pose fly(const scene::Pose& from, const config::Navigation& settings, double x, double y,
                              const std::optional<glm::dvec3>& pointing, const glm::dvec3& eyes, double seconds);

class ViewerNavigation {
 public:
  // `navigation`: viewer.navigation (none: only what applications set);
  // `tracking`: where the tracker is in the installation (the flysticks'
  // poses), none without a tracker.
  ViewerNavigation(std::optional<config::Navigation> navigation, std::optional<config::Tracking> tracking,
                   clock::Nanos period);

  // The newest of each flystick the tracker's reader brought.
  void input(const std::vector<tracking::FlystickSample>& flysticks);

  // Frame `frame`: `state.navigation` as the live scene put it (set `sets`
  // times by applications; put_live), flown on a period by the flystick
  // from where the last frame left it, now and a period later. The flysticks
  // that changed since the last frame go to `events`.
  void step(std::uint64_t frame, scene::SceneState& state, std::uint64_t sets, std::vector<session::Event>& events);

 private:
  struct Stick {
    tracking::FlystickSample newest;
    std::optional<tracking::InstallationPose> seen;  // its last pose seen
    bool changed = false;                            // since the last step
  };

  std::optional<config::Navigation> settings_;
  std::optional<config::Tracking> tracking_;
  double seconds_;  // a period
  std::map<std::uint32_t, Stick> sticks_;
  scene::Pose at_;    // where the next frame begins
  scene::Pose home_;  // where applications last set it: the reset button's
  std::uint64_t sets_seen_ = 0;
  bool reset_held_ = false;
};

}  // namespace optique::master
