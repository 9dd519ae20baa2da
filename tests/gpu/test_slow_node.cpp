// A GL node that draws slower than the frame period (many lights on llvmpipe),
// stopped for a second and let go: it must come back, be waited for again and
// show nearly every frame from then on (issue: a slow node never came back, it
// drew every frame it had been sent one after another and fell ever further
// behind).

#include <gtest/gtest.h>

#include <csignal>
#include <thread>

#include "clock/clock.h"
#include "cluster_run.h"
#include "external_master.h"
#include "screen_check.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

TEST(SlowNode, AStoppedGlNodeSlowerThanThePeriodComesBackAndShowsTheFramesAfter) {
  const ScratchDir dir_scratch("optique-slow");
  const std::string dir = dir_scratch.string();
  const std::string config = write_config_variant(
      OPTIQUE_SOURCE_DIR "/configs/single-wall.json",
      [](schema::Installation& installation) { installation.mutable_scene()->set_builtin("many-lights"); },
      dir + "/slow.json");
  ExternalMaster master(config, {"--frames", "60"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto node = master.node("wall", {"--renderer", "gl"});
  // Said after its first frame: it draws slower than the period, so the run
  // lasts long enough after the stop to tell, however fast this machine draws.
  ASSERT_TRUE(master.process->wait_for_output("longer than the 16.7 ms frame period", 60s)) << master.process->output();
  std::this_thread::sleep_for(300ms);
  node->signal(SIGSTOP);
  std::this_thread::sleep_for(1s);
  const clock::Nanos back = clock::monotonic_now();
  node->signal(SIGCONT);

  ASSERT_EQ(master.process->wait(120s).value_or(-1), 0) << master.process->output();
  EXPECT_EQ(node->wait(10s), 0) << node->output();
  const std::string said = master.process->output();
  EXPECT_NE(said.find("taken out of the barrier"), std::string::npos) << said;
  EXPECT_NE(said.find("back in the barrier"), std::string::npos) << said;
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  std::uint64_t after = 0;
  std::uint64_t shown_after = 0;
  for (const FrameRow& row : run.rows) {
    if (row.begin_sent < back) continue;
    ++after;
    if (row.presented != 0) ++shown_after;
  }
  ASSERT_GE(after, 10u) << "the run went on long enough after the node was back to tell";
  EXPECT_GE(static_cast<double>(shown_after), 0.9 * static_cast<double>(after))
      << shown_after << " of the " << after << " frames begun after it was back were shown\n"
      << said;
}

}  // namespace
}  // namespace optique::testing
