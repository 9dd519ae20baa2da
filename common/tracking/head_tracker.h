#pragma once
// The master's tracked head, without IO: samples in (DTrack datagrams as they
// arrive, or a replay's samples at their times), each stamped on the master's
// clock as the moment it shows (arrival − the tracker's own latency − the
// configured latency), carried from tracker space to the world and to the eyes'
// centre; out, the head predicted at a frame's display time.
//
// What it ignores, and counts: datagrams that do not parse (garbage, NaN, a
// matrix that is not a rotation), frames without the configured body, frames
// older than the last one (a frame counter or timestamp that goes backwards;
// far backwards, or backwards for half a second, is a tracker that restarted,
// and is followed), and datagrams that come sooner than kFloodInterval after
// the last one read, or samples less than kLeastSampleInterval after the last
// one taken (a flood is dropped unread: it costs the io thread a receive each).
//
// Lost (no sample for `lost_after`): the pose shown as it went quiet is held for
// `hold`, then eased (smoothstep) over `ease` to where the viewer rests (its eye
// or path, its eyes along the world's x); back on the first sample. Each loss and each
// return is said once.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/tracking.h"
#include "tracking/predictor.h"
#include "tracking/replay.h"

namespace optique::tracking {

inline constexpr Nanos kFloodInterval = 500'000;  // 2 kHz: DTrack sends at most 300 frames a second
// The senders whose last datagram is remembered for the flood rule; beyond
// these, the one heard from longest ago is forgotten.
inline constexpr std::size_t kMostSenders = 64;

enum class TrackerState { waiting, tracking, holding, easing, resting };
[[nodiscard]] std::string_view to_string(TrackerState state);

struct TrackingCounts {
  std::uint64_t datagrams = 0;     // received (flood included)
  std::uint64_t samples = 0;       // taken
  std::uint64_t malformed = 0;     // did not parse: garbage, NaN, not a rotation
  std::uint64_t without_body = 0;  // parsed, but the configured body was not in it
  std::uint64_t backwards = 0;     // older than the last sample taken
  std::uint64_t flood = 0;         // dropped unread, too soon after the sender's last
  std::uint64_t other_sender = 0;  // dropped unread, not from viewer.tracking.from
  std::uint64_t losses = 0;        // times the tracker was lost
  Nanos lost_ns = 0;               // time spent lost, up to the last frame
};

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

  // A DTrack datagram that arrived at `arrival` (master clock) from `sender`
  // (its address). What is worth a log line (the first of each kind of refusal;
  // further ones are counted). The flood rule is each sender's: a host that
  // floods the port does not starve the tracker.
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

  config::Tracking settings_;
  glm::dquat rest_turn_;
  HeadPredictor predictor_;
  HeadPose held_;       // where the eyes were shown as the tracker went quiet
  double eased_ = 0.0;  // how far from held_ to the rest, as of the last notice (smoothstep)
  int backwards_in_a_row_ = 0;
  TrackingCounts counts_;
  TrackerState state_ = TrackerState::waiting;
  std::map<std::string, Nanos, std::less<>> last_read_;  // each sender's last datagram parsed (flood)
  std::optional<Nanos> last_arrival_;                    // the last sample taken
  std::optional<std::uint64_t> last_frame_;
  std::optional<double> last_timestamp_;
  std::optional<Nanos> lost_since_;
  std::optional<Nanos> last_now_;
  bool said_malformed_ = false;
  bool said_without_body_ = false;
  bool said_backwards_ = false;
  bool said_flood_ = false;
  bool said_other_sender_ = false;
};

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
