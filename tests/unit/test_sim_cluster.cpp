// A whole cluster of protocol cores on simulated links (tests/support/sim_cluster.h):
// the runs the process tests make, in milliseconds and without timing noise.

#include "sim_cluster.h"

#include <gtest/gtest.h>

#include <numeric>

namespace optique::testing {
namespace {

constexpr clock::Nanos kSecond = clock::kNanosPerSecond;

master::RunConfig load(const std::string& name) {
  auto loaded = master::load_run_config(std::string(OPTIQUE_SOURCE_DIR) + "/configs/" + name, {});
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  return loaded ? std::move(loaded).value() : master::RunConfig{};
}

std::vector<std::uint64_t> frames(std::uint64_t first, std::uint64_t end) {
  std::vector<std::uint64_t> v(end - first);
  std::iota(v.begin(), v.end(), first);
  return v;
}

master::RunSettings for_frames(std::uint64_t count) {
  master::RunSettings settings;
  settings.frames = count;
  return settings;
}

TEST(SimCluster, EveryNodeShowsEveryFrameAndTheRunEndsCleanly) {
  const master::RunConfig run = load("powerwall-2x2.json");
  SimCluster cluster(run, for_frames(30));
  cluster.start();
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  ASSERT_TRUE(cluster.master_finished());
  EXPECT_EQ(cluster.exit_code(), master::kExitOk);
  for (std::size_t i = 0; i < cluster.nodes(); ++i) EXPECT_EQ(cluster.presented(i), frames(0, 30)) << i;
  const report::RunReport report = cluster.master().report();
  EXPECT_EQ(report.frames(), 30u);
  EXPECT_EQ(report.sync().frames_with_missing_node(), 0u);
  EXPECT_EQ(report.sync().present_skew_us().max(), 0.0) << "one clock: every node presents at the deadline";
}

// An application's edit made before frame k begins is drawn in frame k by
// every node, and not before; the nodes' states keep the master's hash.
// Also where a projector interpolates between key frames drawn ahead (the
// state sent ahead carries the instances as they are when it is sent).
class LiveEdits : public ::testing::TestWithParam<const char*> {};

TEST_P(LiveEdits, AnEditBeforeAFrameBeginsIsInThatFrameOnEveryNode) {
  const master::RunConfig run = load(GetParam());
  master::LiveScene live;
  live.add_asset("torus");
  master::RunSettings settings = for_frames(30);
  settings.live = &live;
  SimCluster cluster(run, settings);
  cluster.start();
  cluster.run_promptly(cluster.now() + kSecond / 6);  // about ten frames in
  const std::uint64_t k = cluster.master().progress().next_frame;
  ASSERT_GT(k, 2u);
  ASSERT_LT(k, 25u);
  session::Transaction create;
  create.add_edits()->mutable_create()->set_instance("t1");
  create.mutable_edits(0)->mutable_create()->set_asset("torus");
  ASSERT_FALSE(live.apply(create, k));
  cluster.scene_edited();  // staged to the nodes now, or after the round under way
  // Moved on every frame from here: staged between rounds each time.
  for (int moves = 0; moves < 10; ++moves) {
    cluster.run_promptly(cluster.now() + kSecond / 60);
    session::Transaction move;
    move.add_edits()->mutable_transform()->set_instance("t1");
    for (double x : {0.1 * moves, 1.0, -1.0})
      move.mutable_edits(0)->mutable_transform()->mutable_transform()->add_position(x);
    ASSERT_FALSE(live.apply(move, cluster.master().progress().next_frame));
    cluster.scene_edited();
  }
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  const report::RunReport report = cluster.master().report();
  for (std::size_t i = 0; i < cluster.nodes(); ++i) {
    EXPECT_EQ(cluster.presented(i), frames(0, 30)) << i;
    EXPECT_EQ(report.nodes(static_cast<int>(i)).hash_mismatches(), 0u) << i;
    for (std::uint64_t frame = 0; frame < 30; ++frame) {
      const auto& drawn = cluster.instances_drawn(i);
      const bool has = drawn.contains(frame) && drawn.at(frame).contains("t1");
      EXPECT_EQ(has, frame >= k) << "node " << i << ", frame " << frame << ", edit before frame " << k;
    }
    // Sent ahead: the instances as they are when the frame that carries them begins.
    for (const auto& [frame, ahead] : cluster.instances_ahead(i)) {
      EXPECT_EQ(ahead.contains("t1"), frame >= k) << "node " << i << ", ahead with frame " << frame;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Configs, LiveEdits, ::testing::Values("powerwall-2x2.json", "stacked-upconversion.json"));

// A recorded session played again (--replay): each transaction in the frame
// it was in, on every node, with no application connected.
TEST(SimCluster, AReplayedJournalPutsEachTransactionInItsFrame) {
  const master::RunConfig run = load("powerwall-2x2.json");
  session::Transaction create;
  create.add_edits()->mutable_create()->set_instance("t1");
  create.mutable_edits(0)->mutable_create()->set_asset("torus");
  session::Transaction remove;
  remove.add_edits()->mutable_remove()->set_instance("t1");
  auto journal = master::read_journal(std::string(master::kJournalMagic) + master::journal_start(0, "torus") +
                                      master::journal_transaction(4, "app", create) +
                                      master::journal_transaction(11, "app", remove));
  ASSERT_TRUE(journal.ok()) << journal.error();
  master::LiveScene live;
  live.add_asset("torus");
  auto replay = master::JournalReplay::start(journal.value(), live);
  ASSERT_TRUE(replay.ok()) << replay.error();
  master::RunSettings settings = for_frames(20);
  settings.live = &live;
  settings.journal_replay = &replay.value();
  SimCluster cluster(run, settings);
  cluster.start();
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  for (std::size_t i = 0; i < cluster.nodes(); ++i) {
    EXPECT_EQ(cluster.presented(i), frames(0, 20)) << i;
    EXPECT_EQ(cluster.master().report().nodes(static_cast<int>(i)).hash_mismatches(), 0u) << i;
    for (std::uint64_t frame = 0; frame < 20; ++frame) {
      const auto& drawn = cluster.instances_drawn(i);
      const bool has = drawn.contains(frame) && drawn.at(frame).contains("t1");
      EXPECT_EQ(has, frame >= 4 && frame < 11) << "node " << i << ", frame " << frame;
    }
  }
}

// With a live scene the master raises, for applications, every frame it
// begins (its display time a period after the last) and the head in it, and
// a node that leaves and comes back.
TEST(SimCluster, TheMasterRaisesFramesHeadsAndNodesForApplications) {
  const master::RunConfig run = load("powerwall-2x2.json");
  master::LiveScene live;
  master::RunSettings settings = for_frames(30);
  settings.live = &live;
  SimCluster cluster(run, settings);
  cluster.start();
  cluster.run_promptly(cluster.now() + kSecond / 4);
  cluster.reset_link(1);
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  std::vector<std::uint64_t> begun;
  std::vector<clock::Nanos> displays;
  std::size_t heads = 0;
  std::vector<std::string> nodes;
  for (const session::Event& event : cluster.app_events()) {
    if (event.has_frame_begun()) {
      begun.push_back(event.frame_begun().frame());
      displays.push_back(event.frame_begun().display_ns());
      EXPECT_NEAR(static_cast<double>(event.frame_begun().period_ns()), 1e9 / 60.0, 1.0);
    }
    if (event.has_head()) {
      ++heads;
      EXPECT_EQ(event.head().frame(), begun.back()) << "after its frame";
      EXPECT_NEAR(event.head().eyes(1), 1.6, 1e-9);  // the config's eyes
      EXPECT_NEAR(event.head().right(0), 1.0, 1e-9);
      EXPECT_FALSE(event.head().tracked());
    }
    if (event.has_node()) {
      nodes.push_back(event.node().projector() + (event.node().up() ? " up " : " down ") +
                      std::to_string(event.node().nodes_up()) + "/" + std::to_string(event.node().nodes()));
    }
  }
  EXPECT_EQ(begun, frames(0, 30));
  EXPECT_EQ(heads, 30u);
  for (std::size_t i = 1; i < displays.size(); ++i) EXPECT_GT(displays[i], displays[i - 1]) << i;
  const std::string id = run.config.installation.projectors[1].id;
  ASSERT_GE(nodes.size(), 6u) << ::testing::PrintToString(nodes);
  EXPECT_EQ(std::vector<std::string>(nodes.end() - 2, nodes.end()),
            (std::vector<std::string>{id + " down 3/4", id + " up 4/4"}));
}

TEST(SimCluster, AWrongStateIsRepairedTheNextFrame) {
  const master::RunConfig run = load("powerwall-2x2.json");
  SimCluster cluster(run, for_frames(20), 5);
  cluster.start();
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  const report::RunReport report = cluster.master().report();
  EXPECT_EQ(report.nodes(0).hash_mismatches(), 1u) << "reported once, repaired at once";
  EXPECT_EQ(cluster.presented(0), frames(0, 20));
}

TEST(SimCluster, ANodeWhoseLinkBreaksRejoinsAndShowsEveryFrameFromThereOn) {
  const master::RunConfig run = load("powerwall-2x2.json");
  SimCluster cluster(run, for_frames(60));
  cluster.start();
  cluster.run_promptly(cluster.now() + kSecond / 4);  // about 15 frames
  const std::uint64_t before = cluster.presented(2).back();
  cluster.reset_link(2);
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  ASSERT_TRUE(cluster.master_finished());
  const auto& shown = cluster.presented(2);
  const auto back = std::find_if(shown.begin(), shown.end(), [&](std::uint64_t f) { return f > before; });
  ASSERT_NE(back, shown.end());
  EXPECT_EQ(std::vector<std::uint64_t>(back, shown.end()), frames(*back, 60)) << "no frame skipped after the rejoin";
  EXPECT_EQ(cluster.master().report().nodes(2).joins(), 2u);
  EXPECT_EQ(cluster.presented(0), frames(0, 60)) << "the others never stopped";
}

// Assets loaded while the frames go on: usable once every node has answered,
// each offered once to each connection; a node that rejoins gets them in its
// welcome (not offered again), and later ones are offered to it too. Every
// frame is shown throughout.
TEST(SimCluster, AssetsLoadedInTheFramesAreUsableOnceAndEveryFrameIsShown) {
  const master::RunConfig run = load("powerwall-2x2.json");
  SimCluster cluster(run, for_frames(60));
  cluster.start();
  cluster.run_promptly(cluster.now() + kSecond / 6);
  cluster.add_asset();
  EXPECT_EQ(cluster.asset_news(), std::vector<std::string>{}) << "not before the nodes answer";
  cluster.run_promptly(cluster.now() + kSecond / 6);
  EXPECT_EQ(cluster.asset_news(), std::vector<std::string>{"usable asset-0"});
  cluster.reset_link(1);
  cluster.run_promptly(cluster.now() + kSecond / 6);
  cluster.add_asset();
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  ASSERT_TRUE(cluster.master_finished());
  EXPECT_EQ(cluster.asset_news(), (std::vector<std::string>{"usable asset-0", "usable asset-1"}));
  EXPECT_EQ(cluster.presented(0), frames(0, 60));
}

TEST(SimCluster, AnAutomaticGroupKeepsGoingWhenANodeIsLost) {
  const master::RunConfig run = load("stacked-lighting-3-auto.json");
  SimCluster cluster(run, for_frames(40));
  cluster.start();
  cluster.run_promptly(cluster.now() + kSecond / 6);
  cluster.reset_link(1);
  cluster.run_promptly(cluster.now() + 10 * kSecond);
  EXPECT_EQ(cluster.violations(), std::vector<std::string>{});
  EXPECT_EQ(cluster.presented(0), frames(0, 40));
  EXPECT_EQ(cluster.presented(2), frames(0, 40));
}

}  // namespace
}  // namespace optique::testing
