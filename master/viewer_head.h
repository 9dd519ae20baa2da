#pragma once
// The viewer's tracked head as the master shows it (viewer.tracking): the
// tracker's samples, or a replay's at their times; the head predicted to each
// frame's display time and put into the frame's state; what the run reports of
// the tracking. One unit the master's frame loop asks, apart from it; the head
// shown each frame leaves as an action (HeadShown) for the shell's head.csv.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "clock/clock.h"
#include "config/installation.h"
#include "optique/report.pb.h"
#include "scene/state.h"
#include "tracking/head_tracker.h"

namespace optique::master {

// The head shown in a frame: the frame, its display time (master clock), the
// tracker's state then, the eyes' centre and the axis to the right eye.
struct HeadShown {
  std::uint64_t frame = 0;
  clock::Nanos display = 0;
  tracking::TrackerState tracker = tracking::TrackerState::waiting;
  glm::dvec3 eye{0.0};
  glm::dvec3 right{0.0};
};

// head.csv: its header, and a row for a frame (both end with a newline).
[[nodiscard]] std::string head_csv_header();
[[nodiscard]] std::string head_csv_row(const HeadShown& shown);

class ViewerHead {
 public:
  // `replay`: a replay tracker's samples, fed from start() on at their times.
  ViewerHead(const config::Tracking& tracking, const glm::dvec3& head_right, clock::Nanos frame_period,
             std::vector<tracking::ReplaySample> replay);

  void start(clock::Nanos now);
  // What the tracker's reader brought (master/app/tracker_receiver.h); what it has
  // to say goes to `said`.
  void input(tracking::TrackerInput input, std::vector<std::string>& said);
  // The frame's head: a replay fed up to `now`, a loss noticed (said), the head
  // at `display` and a period later put into `state`.
  [[nodiscard]] HeadShown track(scene::SceneState& state, std::uint64_t frame, clock::Nanos display, clock::Nanos now,
                                std::vector<std::string>& said);
  // The head at `display` and a period later into `state` (a scene sent ahead:
  // a prediction that far ahead), as of the last track().
  [[nodiscard]] tracking::TrackerState into(scene::SceneState& state, clock::Nanos display) const;
  [[nodiscard]] report::TrackingReport report() const;

 private:
  const config::Tracking& tracking_;
  glm::dvec3 head_right_;
  clock::Nanos period_;
  tracking::HeadTracker tracker_;
  std::vector<tracking::ReplaySample> replay_samples_;  // until start()
  std::optional<tracking::ReplayFeed> replay_;
};

}  // namespace optique::master
