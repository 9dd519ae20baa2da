// Every shipped config, with --local GL nodes, beside two busy loops that keep
// both cores of this machine busy: the nodes come up, and nearly every frame
// is shown by every projector. (Before nodes drew a warm-up frame and the
// barrier allowed for it, a loaded machine lost every node at frame 0.)

#include <gtest/gtest.h>

#include <csignal>

#include "cluster_run.h"
#include "process.h"
#include "shipped_configs.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";
constexpr int kFrames = 20;

class UnderLoad : public ::testing::TestWithParam<std::string> {};

TEST_P(UnderLoad, NearlyEveryFrameIsShownByEveryProjector) {
  const std::string dir = make_temp_dir("optique-load");
  std::vector<std::unique_ptr<Process>> busy;
  for (int i = 0; i < 2; ++i) {
    busy.push_back(std::make_unique<Process>(std::vector<std::string>{"/bin/sh", "-c", "while :; do :; done"},
                                             dir + "/busy-" + std::to_string(i) + ".log"));
  }
  Process master({std::string(OPTIQUE_BIN_DIR) + "/optique-master", "--config", kConfigs + "/" + GetParam(),
                  "--local", "--frames", std::to_string(kFrames), "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  const auto status = master.wait(scaled(240s));
  for (auto& loop : busy) loop->signal(SIGKILL);
  ASSERT_TRUE(status.has_value()) << "still running after 240 s:\n" << master.output();
  ASSERT_EQ(*status, 0) << master.output();
  const ClusterRun run = read_cluster_run(dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  ASSERT_EQ(run.report.frames(), static_cast<std::uint64_t>(kFrames));
  const std::uint64_t shown_by_all = run.report.frames() - run.report.sync().frames_with_missing_node();
  EXPECT_GE(static_cast<double>(shown_by_all), 0.9 * kFrames)
      << shown_by_all << " of " << kFrames << " frames shown by every projector\n"
      << master.output();
}

INSTANTIATE_TEST_SUITE_P(Configs, UnderLoad, ::testing::ValuesIn(shipped_configs(kConfigs)),
                         [](const auto& param_info) { return config_test_name(param_info.param); });

}  // namespace
}  // namespace optique::testing
