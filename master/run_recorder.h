#pragma once
// What happened to every frame on every node, in master-clock nanoseconds:
// handed over as frames.csv rows as frames complete (master/frame_rows.h), and
// folded into the run.json summary. Writes no file.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "clock/clock.h"
#include "master/frame_rows.h"
#include "metrics/distribution.h"
#include "optique/report.pb.h"
#include "optique/wire.pb.h"

namespace optique::master {

// A node that up-converts: the key frames listed in run.json, at most (a day
// at 60 Hz and 4:1 would be 1.3 million); all are counted.
inline constexpr std::size_t kMostKeyFramesListed = 100000;

// The last frames finalized, for the live status: ten seconds at 60 Hz.
inline constexpr std::size_t kRecentFrames = 600;

// What a node reports is bounded here, at the recorder's door, whatever sent it
// (an authenticated node may still be broken, or hostile): a value beyond these
// enters neither run.json nor the live status, and is counted in its node's
// `out_of_range`.
inline constexpr clock::Nanos kLongestRender = 60 * clock::kNanosPerSecond;
// From the frame's Swap, either way.
inline constexpr clock::Nanos kFarthestPresent = 60 * clock::kNanosPerSecond;
inline constexpr double kLargestDriftPpm = 1e4;
// Monotonic clocks count from boot: two machines' differ by at most an uptime.
inline constexpr clock::Nanos kLargestClockOffset = 10LL * 365 * 24 * 3600 * clock::kNanosPerSecond;
// A round trip, its half (the error bound), and an estimate's true error.
inline constexpr clock::Nanos kLongestRoundTrip = 60 * clock::kNanosPerSecond;

struct RecentFrame {
  std::uint64_t id = 0;
  clock::Nanos begin_sent = 0;
  std::optional<double> skew_us;  // when two or more nodes presented it
  std::vector<float> render_us;   // per node; negative: not rendered
};

// A node's running totals, cheap to read at any time (no percentiles).
struct NodeCounts {
  std::uint64_t rendered = 0;
  std::uint64_t presented = 0;
  std::uint64_t barrier_misses = 0;
  std::uint64_t hash_mismatches = 0;
  std::uint64_t joins = 0;
  double render_us_sum = 0.0;
  std::uint64_t render_times = 0;  // rendered with a render time in bounds: render_us_sum's count
  std::uint64_t out_of_range = 0;  // values reported beyond the bounds above, not recorded
  report::ClockReport clock;       // the latest estimate in bounds
};

// The run's totals over the finalized frames, cheap to read at any time.
struct RunTotals {
  std::uint64_t frames_finalized = 0;
  std::uint64_t frames_with_missing_node = 0;
  std::uint64_t frames_incoherent = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t frames_shown_by_none = 0;
  // Present skew of the most recently finalized frame that two or more nodes
  // presented, for the status line.
  double last_present_skew_us = 0.0;
  // Over every finalized frame that two or more nodes presented.
  double present_skew_us_sum = 0.0;
  std::uint64_t present_skew_count = 0;
};

// What happened to a node, counted in its NodeCounts.
enum class NodeEvent { joined, missed_barrier, hash_mismatch };

class RunRecorder {
 public:
  explicit RunRecorder(std::vector<std::string> node_ids);

  // `bytes`: the size of the FrameBegin the nodes were sent (before what is
  // each node's own: its share of the lights, a frame ahead).
  void frame_begun(std::uint64_t frame, clock::Nanos sent, const std::vector<std::size_t>& nodes,
                   std::size_t bytes = 0);
  // A staged edit of `bytes` (master/staged_edits.cpp) for the next frame to
  // begin: counted with its FrameBegin in the scene's bytes a frame.
  void staged(std::size_t bytes) { staged_bytes_ += bytes; }
  // `drawn_as`: how a node that up-converts drew it (key frame, between…). A
  // render time beyond kLongestRender (or negative) is counted, not recorded.
  void ready(std::uint64_t frame, std::size_t node, clock::Nanos received, clock::Nanos render_time,
             wire::DrawnAs drawn_as = wire::DRAWN_FULL);
  void swapped(std::uint64_t frame, clock::Nanos sent, const std::vector<std::size_t>& nodes);
  // `content_frame`: the frame whose content the node showed (a node out of step
  // shows an older one: the frame is then incoherent). A time farther than
  // kFarthestPresent from the frame's Swap is counted, not recorded.
  void presented(std::uint64_t frame, std::size_t node, clock::Nanos at, std::uint64_t content_frame);

  // The node's clock estimate at its present of `frame`; one with any field out
  // of bounds (a drift not finite or over kLargestDriftPpm…) is counted and the
  // previous one kept.
  void clock_estimated(std::uint64_t frame, std::size_t node, const report::ClockReport& latest,
                       std::optional<clock::Nanos> true_error);

  // The straggler policy "drop": no node was told to show `frame`.
  void frame_dropped(std::uint64_t frame);

  void node_event(std::size_t node, NodeEvent event);

  // Frames older than `before` (every frame without) can no longer change:
  // summarized, and their frames.csv rows returned.
  [[nodiscard]] std::vector<FrameRow> finalize(std::optional<std::uint64_t> before = std::nullopt);

  // Summary of the finalized frames.
  [[nodiscard]] report::RunReport report() const;

  [[nodiscard]] const RunTotals& totals() const { return run_; }
  [[nodiscard]] const std::deque<RecentFrame>& recent() const { return recent_; }
  [[nodiscard]] const NodeCounts& node_counts(std::size_t node) const { return totals_.at(node).counts; }

 private:
  struct NodeFrame {
    bool begun = false;
    bool swapped = false;
    clock::Nanos ready = 0;
    clock::Nanos presented = 0;
    std::uint64_t content_frame = 0;
    float render_us = -1.0F;
  };
  struct FrameRecord {
    std::uint64_t id = 0;
    clock::Nanos begin_sent = 0;
    clock::Nanos swap_sent = 0;
    std::vector<NodeFrame> nodes;
  };
  struct NodeTotals {
    NodeCounts counts;
    metrics::Reservoir render_us;
    // Up-conversion: frames that showed a key frame, frames between, and the
    // render time of each way of drawing a frame (by wire::DrawnAs).
    std::vector<std::uint64_t> key_frames;  // the first kMostKeyFramesListed
    std::uint64_t key_frames_total = 0;
    std::uint64_t between = 0;
    std::map<int, metrics::Reservoir> render_us_drawn_as;
    metrics::Reservoir clock_true_error_us;
  };

  FrameRecord* find(std::uint64_t frame);
  void finalize(const FrameRecord& record, std::vector<FrameRow>& rows);

  std::vector<std::string> ids_;
  std::deque<FrameRecord> open_;
  std::vector<NodeTotals> totals_;
  metrics::Reservoir barrier_round_us_;
  metrics::Reservoir present_skew_us_;
  metrics::Reservoir frame_begin_bytes_;
  metrics::Reservoir frame_state_bytes_;  // the FrameBegin and the edits staged for its frame
  std::size_t staged_bytes_ = 0;          // for the next frame to begin
  RunTotals run_;
  clock::Nanos first_begin_ = 0;
  clock::Nanos last_begin_ = 0;
  std::deque<RecentFrame> recent_;
};

}  // namespace optique::master
