#include "cluster_run.h"

#include <google/protobuf/util/json_util.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "process.h"

namespace optique::testing {
namespace {

std::int64_t cell(const std::string& text) { return text.empty() ? 0 : std::stoll(text); }

}  // namespace

ClusterRun read_cluster_run(const std::string& out_dir) {
  ClusterRun run;
  std::ifstream json_file(out_dir + "/run.json");
  if (!json_file) {
    run.error = "no run.json in " + out_dir;
    return run;
  }
  std::ostringstream json;
  json << json_file.rdbuf();
  const auto status = google::protobuf::util::JsonStringToMessage(json.str(), &run.report);
  if (!status.ok()) {
    run.error = "run.json: " + std::string(status.message());
    return run;
  }
  std::ifstream csv(out_dir + "/frames.csv");
  std::string line;
  if (!std::getline(csv, line) || line != "frame_id,node,begin_sent_ns,ready_received_ns,swap_sent_ns,presented_ns") {
    run.error = "frames.csv: missing or unexpected header";
    return run;
  }
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) cells.push_back(field);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    if (cells.size() != 6) {
      run.error = "frames.csv: bad row '" + line + "'";
      return run;
    }
    run.rows.push_back(
        {std::stoull(cells[0]), cells[1], cell(cells[2]), cell(cells[3]), cell(cells[4]), cell(cells[5])});
  }
  return run;
}

std::vector<std::string> sync_problems(const ClusterRun& run, const std::vector<std::string>& nodes,
                                       std::uint64_t frames) {
  std::vector<std::string> problems;
  std::map<std::uint64_t, std::map<std::string, std::int64_t>> presented;
  for (const FrameRow& row : run.rows) {
    if (row.presented != 0) presented[row.frame][row.node] = row.presented;
  }
  std::int64_t previous_last = std::numeric_limits<std::int64_t>::min();
  for (std::uint64_t frame = 0; frame < frames; ++frame) {
    const auto& shown = presented[frame];
    std::int64_t first = std::numeric_limits<std::int64_t>::max();
    std::int64_t last = std::numeric_limits<std::int64_t>::min();
    for (const auto& node : nodes) {
      const auto it = shown.find(node);
      if (it == shown.end()) {
        problems.push_back("frame " + std::to_string(frame) + ": node '" + node + "' did not present it");
        continue;
      }
      first = std::min(first, it->second);
      last = std::max(last, it->second);
    }
    if (!shown.empty() && first <= previous_last) {
      problems.push_back("frame " + std::to_string(frame) + " was presented before every node had presented frame " +
                         std::to_string(frame - 1));
    }
    if (!shown.empty()) previous_last = last;
  }
  return problems;
}

const report::NodeReport* find_node(const report::RunReport& report, const std::string& id) {
  for (const auto& node : report.nodes()) {
    if (node.id() == id) return &node;
  }
  return nullptr;
}

StandInStart start_with_stand_in_nodes(const std::string& master_binary, const std::string& config) {
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  const std::string stand_in = dir + "/stand-in-node";
  std::ofstream(stand_in) << "#!/bin/sh\ntouch " << dir << "/node-started\n";
  std::filesystem::permissions(stand_in, std::filesystem::perms::owner_all);
  StandInStart result;
  result.out_dir = dir + "/out";
  Process master(
      {master_binary, "--config", config, "--local", "--node-binary", stand_in, "--out", result.out_dir, "--no-status"},
      dir + "/master.log");
  result.status = master.wait(std::chrono::seconds(30)).value_or(-1);
  result.output = master.output();
  result.node_started = std::filesystem::exists(dir + "/node-started");
  return result;
}

}  // namespace optique::testing
