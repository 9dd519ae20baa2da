#pragma once
// Reading what a master run wrote (run.json, frames.csv) and checking frame sync
// on it, for the integration tests and the benchmark.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "optique/report.pb.h"

namespace optique::testing {

struct FrameRow {
  std::uint64_t frame = 0;
  std::string node;
  std::int64_t begin_sent = 0;
  std::int64_t ready = 0;      // 0: never
  std::int64_t swap_sent = 0;  // 0: not swapped
  std::int64_t presented = 0;  // 0: never
};

struct ClusterRun {
  report::RunReport report;
  std::vector<FrameRow> rows;
  std::string error;  // non-empty when the files could not be read
};

[[nodiscard]] ClusterRun read_cluster_run(const std::string& out_dir);

// Problems with frame sync among `nodes` over frames [0, frames): a frame some node
// did not present, presents out of order, or two frames on screen at once (the
// last present of frame k after the first present of k + 1). Empty when in sync.
[[nodiscard]] std::vector<std::string> sync_problems(const ClusterRun& run, const std::vector<std::string>& nodes,
                                                     std::uint64_t frames);

[[nodiscard]] const report::NodeReport* find_node(const report::RunReport& report, const std::string& id);

// A master started with `config` and --local, whose node binary is a stand-in
// that only leaves a mark: did the master start anything, and what did it say?
struct StandInStart {
  int status = -1;  // exit status, -1 if it was still running after 30 s
  std::string output;
  std::string out_dir;
  bool node_started = false;
};
[[nodiscard]] StandInStart start_with_stand_in_nodes(const std::string& master_binary, const std::string& config);

}  // namespace optique::testing
