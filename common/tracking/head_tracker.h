#pragma once
// The master's tracked head, without IO: samples in (DTrack's, as the reader
// hands them over, or a replay's at their times), each stamped on the master's
// clock as the moment it shows (arrival − the tracker's own latency − the
// configured latency), carried from tracker space to the world and to the eyes'
// centre; out, the head predicted at a frame's display time.
//
// What it ignores, and counts, besides what the reader dropped
// (tracking/dtrack_reader.h): frames out of the tracker's sequence
// (tracking/sequence.h: older than the newest taken, or further ahead than the
// time since could bring; a new sequence that goes on is a tracker that
// restarted, and is followed), and samples that show the head no later than, or
// less than kLeastSampleInterval after, the last one taken.
//
// Lost (no sample for `lost_after`): the pose shown as it went quiet is held for
// `hold`, then eased (smoothstep) over `ease` to where the viewer rests (its eye
// or path, its eyes along the world's x); back on the first sample. Each loss and each
// return is said once; so is a DTrack that has sent nothing kQuietStart after the
// first frame (where the master listens), and its first sample after that.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/tracking.h"
#include "tracking/counts.h"
#include "tracking/dtrack_reader.h"
#include "tracking/predictor.h"
#include "tracking/replay.h"
#include "tracking/sequence.h"

namespace optique::tracking {

// No sample this long after the first frame: said, with where the master listens.
inline constexpr Nanos kQuietStart = 2'000'000'000;

enum class TrackerState { waiting, tracking, holding, easing, resting };
[[nodiscard]] std::string_view to_string(TrackerState state);

struct HeadAt {
  HeadPose pose;
  TrackerState state = TrackerState::waiting;
};

class HeadTracker {
 public:
  // `rest_turn`: the head's turn where it rests (waiting for a first sample,
  // or eased to after a loss): the viewer's head_right, in the body's frame,
  // turned to the world's right (the master's: rotation(head_right, x)).
  explicit HeadTracker(const config::Tracking& settings, const glm::dquat& rest_turn = {1.0, 0.0, 0.0, 0.0});

  // What the reader handed over: its samples taken or refused, its counts
  // added; what is worth a log line (the first of each kind of refusal, a
  // restart) into `said`.
  void input(TrackerInput input, std::vector<std::string>& said);
  // A DTrack datagram that arrived at `arrival` (master clock) from `sender`
  // (its address), read here and taken at once: the reader and the tracker on
  // one thread (tests, the bench, the fuzzer). What is worth a log line, joined.
  [[nodiscard]] std::optional<std::string> datagram(std::string_view bytes, Nanos arrival,
                                                    std::string_view sender = {});
  // A sample in tracker space (metres) that shows the head at `time` and
  // arrived then (replay).
  void sample(Nanos time, const glm::dvec3& position, const glm::dquat& orientation);

  // What the tracker is doing at `now` (lost or back, said into `said`), for
  // the at() calls until the next notice.
  void notice(Nanos now, std::vector<std::string>& said);
  // The head at display time `time`, as of the last notice(); `rest`: the
  // eyes' centre where no tracker says otherwise.
  [[nodiscard]] HeadAt at(Nanos time, const glm::dvec3& rest) const;

  [[nodiscard]] const TrackingCounts& counts() const { return counts_; }
  [[nodiscard]] TrackerState state() const { return state_; }

 private:
  void take(Nanos time, Nanos arrival, const glm::dvec3& position, const glm::dquat& orientation);
  void take_dtrack(const DTrackSample& sample, std::vector<std::string>& said);
  // Whether DTrack has been quiet since the first frame, or has just begun (said).
  void notice_start(Nanos now, std::vector<std::string>& said);

  config::Tracking settings_;
  glm::dquat rest_turn_;
  HeadPredictor predictor_;
  HeadPose held_;        // where the eyes were shown as the tracker went quiet
  double eased_ = 0.0;   // how far from held_ to the rest, as of the last notice (smoothstep)
  DTrackReader reader_;  // for datagram() only
  FrameSequence sequence_;
  TrackingCounts counts_;
  TrackerState state_ = TrackerState::waiting;
  std::optional<Nanos> last_arrival_;  // the last sample taken
  std::optional<Nanos> lost_since_;
  std::optional<Nanos> last_now_;
  std::optional<Nanos> first_now_;  // the first notice: frames began
  bool said_quiet_start_ = false;
  bool said_first_sample_ = false;
  bool said_backwards_ = false;
  bool said_flood_ = false;
};

// A tracked pose (tracker space: metres, and the body's turn) carried into the
// installation by the tracker's placement (viewer.tracking.tracker_axes and
// tracker_origin): the body's position and its turn there.
struct InstallationPose {
  glm::dvec3 position{0.0};
  glm::dquat turn{1.0, 0.0, 0.0, 0.0};
};
[[nodiscard]] InstallationPose to_installation(const config::Tracking& settings, const glm::dvec3& position,
                                               const glm::dquat& orientation);

// The turn that carries `head_right` (a unit vector in the tracked body's
// frame) onto the world's x: the rest turn of a tracked head whose eyes, at
// rest, lie along x as an untracked viewer's do.
[[nodiscard]] glm::dquat turn_onto_x(const glm::dvec3& head_right);

// A replay's samples fed at their times from `start` on the master's clock,
// looped (one loop: the last sample's time and one mean interval; a single
// sample is fed once).
class ReplayFeed {
 public:
  ReplayFeed(std::vector<ReplaySample> samples, Nanos start);
  // Every sample due after the last call, up to `now`, into `tracker`.
  void feed(Nanos now, HeadTracker& tracker);

 private:
  std::vector<ReplaySample> samples_;
  Nanos start_;
  Nanos period_;            // one loop
  std::uint64_t next_ = 0;  // samples fed so far, over every loop
};

}  // namespace optique::tracking
