// Every shipped config, with --local GL nodes, beside two busy loops that keep
// both cores of this machine busy, and a frame timeout shorter than any frame
// takes: the nodes come up, and nearly every frame is shown by every projector.
// (Before the barrier waited for a node as long as its warm-up and its frames
// took, a loaded machine lost nodes at frame 0 and never took them back.)

#include <gtest/gtest.h>

#include <csignal>

#include "cluster_run.h"
#include "process.h"
#include "screen_check.h"
#include "shipped_configs.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";
// A node that stalls past its allowance (the busy loops take its core for
// longer than twice its usual round) misses one frame, sometimes two, and is
// back. Measured here, cave-tracked, 20 runs of 60 frames: 55-60 shown by
// every projector, median 59; with 20 frames a CI run once showed 17. Sixty
// frames and 85 % leave room for three such stalls more than the worst seen;
// a node lost and never taken back shows next to nothing.
constexpr int kFrames = 60;
constexpr double kShownByAll = 0.85;
constexpr std::uint32_t kFrameTimeoutMs = 20;

class UnderLoad : public ::testing::TestWithParam<std::string> {};

TEST_P(UnderLoad, NearlyEveryFrameIsShownByEveryProjector) {
  const ScratchDir dir_scratch("optique-load");
  const std::string dir = dir_scratch.string();
  std::vector<std::unique_ptr<Process>> busy;
  for (int i = 0; i < 2; ++i) {
    busy.push_back(std::make_unique<Process>(std::vector<std::string>{"/bin/sh", "-c", "while :; do :; done"},
                                             dir + "/busy-" + std::to_string(i) + ".log"));
  }
  // A frame timeout far below what a frame takes here (llvmpipe on two busy
  // cores: 30-300 ms): the barrier must wait for each node as long as it
  // usually takes, the first frame as long as its warm-up, not drop them.
  const std::string config = write_config_variant(
      kConfigs + "/" + GetParam(),
      [](schema::Installation& installation) { installation.mutable_master()->set_frame_timeout_ms(kFrameTimeoutMs); },
      dir + "/" + GetParam());
  Process master({std::string(OPTIQUE_BIN_DIR) + "/optique-master", "--config", config, "--local", "--frames",
                  std::to_string(kFrames), "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  const auto status = master.wait(scaled(240s));
  for (auto& loop : busy) loop->signal(SIGKILL);
  ASSERT_TRUE(status.has_value()) << "still running after 240 s:\n" << master.output();
  ASSERT_EQ(*status, 0) << master.output();
  const ClusterRun run = read_cluster_run(dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  ASSERT_EQ(run.report.frames(), static_cast<std::uint64_t>(kFrames));
  const std::uint64_t shown_by_all = run.report.frames() - run.report.sync().frames_with_missing_node();
  EXPECT_GE(static_cast<double>(shown_by_all), kShownByAll * kFrames)
      << shown_by_all << " of " << kFrames << " frames shown by every projector\n"
      << master.output();
}

INSTANTIATE_TEST_SUITE_P(Configs, UnderLoad, ::testing::ValuesIn(shipped_configs(kConfigs)),
                         [](const auto& param_info) { return config_test_name(param_info.param); });

}  // namespace
}  // namespace optique::testing
