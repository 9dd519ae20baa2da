#include "master/viewer_head.h"

#include <fmt/format.h>

namespace optique::master {

std::string head_csv_header() { return "frame_id,display_ns,tracker,eye_x,eye_y,eye_z,right_x,right_y,right_z\n"; }

std::string head_csv_row(const HeadShown& shown) {
  return fmt::format("{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f}\n", shown.frame, shown.display,
                     tracking::to_string(shown.tracker), shown.eye.x, shown.eye.y, shown.eye.z, shown.right.x,
                     shown.right.y, shown.right.z);
}

ViewerHead::ViewerHead(const config::Tracking& tracking, const glm::dvec3& head_right, clock::Nanos frame_period,
                       std::vector<tracking::ReplaySample> replay)
    : tracking_(tracking),
      head_right_(head_right),
      period_(frame_period),
      tracker_(tracking, tracking::turn_onto_x(head_right)),
      replay_samples_(std::move(replay)) {}

void ViewerHead::start(clock::Nanos now) {
  if (!replay_samples_.empty()) replay_.emplace(std::move(replay_samples_), now);
  replay_samples_.clear();
}

void ViewerHead::input(tracking::TrackerInput input, std::vector<std::string>& said) {
  tracker_.input(std::move(input), said);
}

tracking::TrackerState ViewerHead::into(scene::SceneState& state, clock::Nanos display) const {
  // Where the viewer rests (eye or path) is what the scene's authority gave.
  const tracking::HeadAt now_head = tracker_.at(display, state.eye_now);
  const tracking::HeadAt next_head = tracker_.at(display + period_, state.eye_next);
  state.eye_now = now_head.pose.position;
  state.eye_next = next_head.pose.position;
  state.head_now = now_head.pose.orientation;
  state.head_next = next_head.pose.orientation;
  return now_head.state;
}

HeadShown ViewerHead::track(scene::SceneState& state, std::uint64_t frame, clock::Nanos display, clock::Nanos now,
                            std::vector<std::string>& said) {
  if (replay_) replay_->feed(now, tracker_);
  tracker_.notice(now, said);
  const tracking::TrackerState tracker = into(state, display);
  return HeadShown{frame, display, tracker, state.eye_now, state.head_now * head_right_};
}

report::TrackingReport ViewerHead::report() const {
  const tracking::TrackingCounts& counts = tracker_.counts();
  report::TrackingReport t;
  t.set_source(std::string(config::to_string(tracking_.source)));
  t.set_prediction(std::string(config::to_string(tracking_.prediction)));
  t.set_datagrams(counts.datagrams);
  t.set_samples(counts.samples);
  t.set_malformed(counts.malformed);
  t.set_without_body(counts.without_body);
  t.set_backwards(counts.backwards);
  t.set_flood(counts.flood);
  t.set_other_sender(counts.other_sender);
  t.set_losses(counts.losses);
  t.set_lost_seconds(static_cast<double>(counts.lost_ns) / 1e9);
  t.set_state(std::string(tracking::to_string(tracker_.state())));
  return t;
}

}  // namespace optique::master
