// Real master and node processes on 127.0.0.1, as a user would run them.

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <thread>

#include "cluster_run.h"
#include "config/load.h"
#include "external_master.h"
#include "process.h"
#include "shipped_configs.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kNode = std::string(OPTIQUE_BIN_DIR) + "/optique-node";
const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

std::vector<std::string> projector_ids(const std::string& config) {
  auto loaded = config::load_installation(config);
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error());
  std::vector<std::string> ids;
  if (loaded.ok()) {
    for (const auto& p : loaded.value().installation.projectors) ids.push_back(p.id);
  }
  return ids;
}

// ------------------------------------------------------------- every shipped config

class ShippedConfig : public ::testing::TestWithParam<std::string> {};

TEST_P(ShippedConfig, RunsSixtyFramesInSyncWithLocalNodes) {
  const std::string config = kConfigs + "/" + GetParam();
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  Process master({kMaster, "--config", config, "--local", "--frames", "60", "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  const auto status = master.wait(60s);
  ASSERT_TRUE(status.has_value()) << "master still running after 60 s:\n" << master.output();
  ASSERT_EQ(*status, 0) << master.output();

  const ClusterRun run = read_cluster_run(dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const auto ids = projector_ids(config);
  EXPECT_EQ(run.report.frames(), 60u);
  EXPECT_EQ(run.report.nodes_configured(), ids.size());
  for (const auto& id : ids) {
    const auto* node = find_node(run.report, id);
    ASSERT_NE(node, nullptr) << id;
    EXPECT_EQ(node->frames_rendered(), 60u) << id;
    EXPECT_EQ(node->frames_presented(), 60u) << id;
    EXPECT_EQ(node->hash_mismatches(), 0u) << id;
    EXPECT_EQ(node->barrier_misses(), 0u) << id;
  }
  EXPECT_EQ(run.report.sync().frames_with_missing_node(), 0u);
  EXPECT_EQ(run.report.sync().frames_incoherent(), 0u);
  EXPECT_EQ(run.rows.size(), 60u * ids.size());
  const auto problems = sync_problems(run, ids, 60);
  EXPECT_TRUE(problems.empty()) << problems.front();
  // Every local node exited after the master's goodbye.
  for (const auto& id : ids) {
    const std::string log = read_file(dir + "/out/logs/" + id + ".log");
    EXPECT_NE(log.find("the master said goodbye"), std::string::npos) << id << ":\n" << log;
  }
}

INSTANTIATE_TEST_SUITE_P(Configs, ShippedConfig, ::testing::ValuesIn(shipped_configs(kConfigs)),
                         [](const auto& param_info) { return config_test_name(param_info.param); });

// ------------------------------------------------------------- failures

TEST(Cluster, KilledNodeLeavesTheBarrierAndTheOthersFinish) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  ExternalMaster master(config, {"--frames", "120"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  std::vector<std::unique_ptr<Process>> nodes;
  for (const auto& id : projector_ids(config)) nodes.push_back(master.node(id));
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 15s)) << master.process->output();
  std::this_thread::sleep_for(500ms);  // about 30 of 120 frames in
  nodes.back()->signal(SIGKILL);

  const auto status = master.process->wait(30s);
  ASSERT_TRUE(status.has_value()) << master.process->output();
  EXPECT_EQ(*status, 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  EXPECT_EQ(run.report.frames(), 120u);
  const auto ids = projector_ids(config);
  const auto* killed = find_node(run.report, ids.back());
  ASSERT_NE(killed, nullptr);
  EXPECT_GT(killed->frames_presented(), 0u);
  EXPECT_LT(killed->frames_presented(), 120u);
  const std::vector<std::string> survivors(ids.begin(), ids.end() - 1);
  for (const auto& id : survivors) EXPECT_EQ(find_node(run.report, id)->frames_presented(), 120u) << id;
  const auto problems = sync_problems(run, survivors, 120);
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_GT(run.report.sync().frames_with_missing_node(), 0u);
  EXPECT_NE(master.process->output().find("node '" + ids.back() + "' left"), std::string::npos)
      << master.process->output();
  for (std::size_t i = 0; i + 1 < nodes.size(); ++i) EXPECT_EQ(nodes[i]->wait(5s), 0) << nodes[i]->output();
}

TEST(Cluster, HungNodeIsTakenOutOfTheBarrierAfterTheTimeout) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  ExternalMaster master(config, {"--frames", "90"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  std::vector<std::unique_ptr<Process>> nodes;
  for (const auto& id : projector_ids(config)) nodes.push_back(master.node(id));
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 15s)) << master.process->output();
  std::this_thread::sleep_for(300ms);  // about 18 of 90 frames in
  nodes.front()->signal(SIGSTOP);

  const auto status = master.process->wait(30s);
  nodes.front()->signal(SIGCONT);
  ASSERT_TRUE(status.has_value()) << master.process->output();
  EXPECT_EQ(*status, 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const auto ids = projector_ids(config);
  const auto* hung = find_node(run.report, ids.front());
  EXPECT_GE(hung->barrier_misses(), 1u);
  EXPECT_LT(hung->frames_presented(), 90u);
  const std::vector<std::string> others(ids.begin() + 1, ids.end());
  for (const auto& id : others) EXPECT_EQ(find_node(run.report, id)->frames_presented(), 90u) << id;
  EXPECT_TRUE(sync_problems(run, others, 90).empty());
  EXPECT_NE(master.process->output().find("taken out of the barrier"), std::string::npos);
}

TEST(Cluster, AStoppedNodeAloneComesBackAfterSigcont) {
  const std::string config = kConfigs + "/single-wall.json";
  ExternalMaster master(config, {"--frames", "240"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto node = master.node("wall");
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 15s)) << master.process->output();
  std::this_thread::sleep_for(500ms);
  node->signal(SIGSTOP);
  std::this_thread::sleep_for(1000ms);  // twice the frame timeout, less than the liveness timeout
  node->signal(SIGCONT);

  ASSERT_EQ(master.process->wait(30s), 0) << master.process->output();
  EXPECT_EQ(node->wait(10s), 0) << node->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const auto* wall = find_node(run.report, "wall");
  EXPECT_GE(wall->barrier_misses(), 1u);
  EXPECT_NE(master.process->output().find("answers again"), std::string::npos) << master.process->output();
  // Back in the barrier: it presents the last frame, and most of the run.
  bool presented_last = false;
  for (const auto& row : run.rows) presented_last |= row.frame == 239 && row.presented != 0;
  EXPECT_TRUE(presented_last);
  EXPECT_GE(wall->frames_presented(), 150u);
}

// A user reads the defaults in --help, not in the source.
TEST(Cluster, NodeHelpShowsTheDefaults) {
  const ScratchDir dir_scratch("optique-help");
  const std::string dir = dir_scratch.string();
  Process help({kNode, "--help"}, dir + "/help.log");
  ASSERT_EQ(help.wait(10s), 0) << help.output();
  const std::string said = help.output();
  EXPECT_NE(said.find("--give-up-after-ms INT:INT in [0 - 86400000]=10000"), std::string::npos) << said;
  EXPECT_NE(said.find("--max-scene-mb UINT:UINT in [1 - 16777216]=8192"), std::string::npos) << said;
}

TEST(Cluster, UnknownNodeIdIsRefusedOnBothSides) {
  ExternalMaster master(kConfigs + "/single-wall.json", {});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto stranger = master.node("no-such-projector");
  const auto status = stranger->wait(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 2);
  EXPECT_NE(stranger->output().find("unknown projector id 'no-such-projector'"), std::string::npos)
      << stranger->output();
  EXPECT_NE(stranger->output().find("wall"), std::string::npos) << "the refusal lists the known ids";
  EXPECT_NE(master.process->output().find("refused node 'no-such-projector'"), std::string::npos)
      << master.process->output();
  master.process->signal(SIGINT);
  EXPECT_EQ(master.process->wait(10s), 0) << master.process->output();
}

TEST(Cluster, ProtocolVersionMismatchIsRefusedOnBothSides) {
  ExternalMaster master(kConfigs + "/single-wall.json", {});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto old_node = master.node("wall", {"--protocol-version", "99"});
  const auto status = old_node->wait(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 2);
  EXPECT_NE(old_node->output().find("protocol version mismatch: node speaks v99"), std::string::npos)
      << old_node->output();
  EXPECT_NE(master.process->output().find("protocol version mismatch"), std::string::npos) << master.process->output();
  master.process->signal(SIGINT);
  EXPECT_EQ(master.process->wait(10s), 0) << master.process->output();
}

TEST(Cluster, ConfigErrorStartsNothing) {
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  const std::string config = dir + "/broken.json";
  std::ofstream(config) << R"({
    "screens": [{"id": "front", "origin": [0, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0], "width": 2, "height": 1}],
    "projectors": [{"id": "p", "width": 320, "height": 180, "screen": "wall"}],
    "viewer": {"eye": [0, 1, 2]},
    "scene": {"builtin": "cubes"}
  })";
  const StandInStart start = start_with_stand_in_nodes(kMaster, config);
  EXPECT_EQ(start.status, 2);
  EXPECT_NE(start.output.find(config + ": projectors[0].screen: unknown screen 'wall'"), std::string::npos)
      << start.output;
  EXPECT_FALSE(start.node_started);
  EXPECT_FALSE(std::filesystem::exists(start.out_dir + "/run.json"));
}

TEST(Cluster, NodeWaitsForALateMasterThenJoins) {
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  const std::string port = free_port();
  Process node({kNode, "--master", "127.0.0.1:" + port, "--id", "wall"}, dir + "/node.log");
  // The node says it is waiting (however long a loaded machine takes to start it).
  EXPECT_TRUE(node.wait_for_output("not reachable", 5s)) << node.output();
  Process master({kMaster, "--config", kConfigs + "/single-wall.json", "--listen", "127.0.0.1", "--port", port,
                  "--frames", "30", "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  ASSERT_EQ(master.wait(30s), 0) << master.output();
  EXPECT_EQ(node.wait(10s), 0) << node.output();
  const ClusterRun run = read_cluster_run(dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  EXPECT_EQ(find_node(run.report, "wall")->frames_presented(), 30u);
}

TEST(Cluster, NodeGivesUpWhenNoMasterComes) {
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  Process node({kNode, "--master", "127.0.0.1:" + free_port(), "--id", "wall", "--give-up-after-ms", "500"},
               dir + "/node.log");
  const auto status = node.wait(10s);
  ASSERT_TRUE(status.has_value());
  EXPECT_EQ(*status, 3);
  EXPECT_NE(node.output().find("gave up"), std::string::npos) << node.output();
}

TEST(Cluster, InterruptStopsTheLocalClusterCleanly) {
  const ScratchDir dir_scratch("optique-it");
  const std::string dir = dir_scratch.string();
  Process master({kMaster, "--config", kConfigs + "/powerwall-2x2.json", "--local", "--port-file", dir + "/port",
                  "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  const std::string port = wait_for_port(dir + "/port", 10s);
  ASSERT_FALSE(port.empty());
  ASSERT_TRUE(master.wait_for_output("starting frames", 15s)) << master.output();
  std::this_thread::sleep_for(500ms);
  master.signal(SIGINT);
  ASSERT_EQ(master.wait(10s), 0) << master.output();
  const ClusterRun run = read_cluster_run(dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  EXPECT_NE(run.report.stopped_because().find("interrupted"), std::string::npos);
  EXPECT_GT(run.report.frames(), 10u);
  EXPECT_TRUE(processes_matching("127.0.0.1:" + port).empty()) << "local nodes outlived the master";
}

}  // namespace
}  // namespace optique::testing
