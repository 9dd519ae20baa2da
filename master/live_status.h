#pragma once
// The master as its operator sees it while it runs: built by the protocol
// (MasterProtocol::live) from what it knows, the recent frames and running
// totals, completed by the shell (uptime, the last warnings, the status
// server's clients), and written out as /status.json (status_json.h) and as
// Prometheus' text format for /metrics (status_metrics.h). Plain values: no
// percentile over the whole run (those are run.json's), only over the last
// frames, so building it at a few hertz costs next to nothing.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "clock/clock.h"
#include "master/run_recorder.h"
#include "optique/report.pb.h"

namespace optique::master {

// Where a projector's node stands.
enum class NodeLink {
  absent,       // never connected
  connecting,   // connected, in the handshake
  configuring,  // welcomed, setting up (GL, scene)
  up,           // in the frame loop
  behind,       // late for a frame: out of the barrier until it answers again
  gone,         // was up, left; may come back
};
[[nodiscard]] std::string_view to_string(NodeLink link);

struct LiveNode {
  std::string id;
  NodeLink link = NodeLink::absent;
  std::string peer;  // address:port while connected
  NodeCounts counts;
  // Render time over the recent frames it rendered.
  std::optional<double> render_ms_median;
  std::optional<double> render_ms_p99;
};

// One recent frame, for the chart.
struct LivePoint {
  std::uint64_t frame = 0;
  std::optional<double> skew_us;
  std::optional<double> frame_ms;  // from this frame's begin to the next's
};

struct LiveWarning {
  std::string time;  // as the log writes it
  std::string text;
};

// The status server's own clients.
struct LiveClients {
  std::uint64_t open = 0;
  std::uint64_t streams = 0;
  std::uint64_t requests = 0;
  std::uint64_t refused = 0;  // busy, too many from one address, too slow, too large, not HTTP, behind
};

struct LiveStatus {
  std::string state;  // starting, running, paused, stopping, done
  std::string config_file;
  double uptime_s = 0.0;
  std::uint64_t next_frame = 0;
  std::uint64_t frames_target = 0;  // 0: until stopped
  double target_rate_hz = 0.0;
  // Over the frames begun in the last two seconds (0 when none, as when paused).
  double frame_rate_hz = 0.0;
  // Over the recent frames (kRecentFrames).
  std::optional<double> skew_us_median;
  std::optional<double> skew_us_p99;
  std::optional<double> frame_ms_median;
  std::uint64_t frames_finalized = 0;
  std::uint64_t frames_with_missing_node = 0;
  std::uint64_t frames_incoherent = 0;
  std::uint64_t frames_dropped = 0;
  double skew_us_sum = 0.0;  // over the whole run, with skew_count: a Prometheus summary
  std::uint64_t skew_count = 0;
  std::size_t nodes_up = 0;
  std::vector<LiveNode> nodes;
  std::optional<report::TrackingReport> tracking;
  std::vector<LiveWarning> warnings;  // oldest first
  std::vector<LivePoint> history;     // oldest first
  LiveClients clients;
};

// How many recent frames the chart shows.
inline constexpr std::size_t kChartFrames = 300;

// The recent frames' share of `status`: rate, skew, frame time, each node's
// render time and the chart. `now` on the same clock as the frames' times.
void summarize_recent(const std::deque<RecentFrame>& recent, clock::Nanos now, LiveStatus& status);

}  // namespace optique::master
