// Per-frame, per-node timing records, frames.csv and the run summary:
// master/run_recorder.h, master/frame_rows.h.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "master/run_recorder.h"

namespace optique::master {
namespace {

constexpr const char* kHeader = "frame_id,node,begin_sent_ns,ready_received_ns,swap_sent_ns,presented_ns";
constexpr double kTolUs = 1e-9;  // values are exact multiples of 1 ns / 1e3

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Two nodes, "a" (slot 0) and "b" (slot 1), through three frames:
//   frame 0: both ready, swapped, presented 30 µs apart; barrier round 600 µs.
//   frame 1: both ready and swapped, b never says Presented; round 800 µs.
//   frame 2: both ready, swapped, presented 70 µs apart (b first); round 400 µs.
void feed_three_frames(RunRecorder& r) {
  const std::vector<std::size_t> both{0, 1};
  r.node_event(0, NodeEvent::joined);
  r.node_event(1, NodeEvent::joined);

  r.frame_begun(0, 1'000'000'000, both);
  r.ready(0, 0, 1'000'300'000, 250'000);
  r.ready(0, 1, 1'000'500'000, 450'000);
  r.swapped(0, 1'000'600'000, both);
  r.presented(0, 0, 1'002'000'000, 0);
  r.presented(0, 1, 1'002'030'000, 0);

  r.frame_begun(1, 1'016'666'667, both);
  r.ready(1, 0, 1'017'000'000, 300'000);
  r.ready(1, 1, 1'017'400'000, 500'000);
  r.swapped(1, 1'017'466'667, both);
  r.presented(1, 0, 1'018'700'000, 1);

  r.frame_begun(2, 1'033'333'333, both);
  r.ready(2, 0, 1'033'500'000, 200'000);
  r.ready(2, 1, 1'033'700'000, 350'000);
  r.swapped(2, 1'033'733'333, both);
  r.presented(2, 0, 1'035'070'000, 2);
  r.presented(2, 1, 1'035'000'000, 2);
}

TEST(RunRecorder, CsvHeaderNamesTheColumns) { EXPECT_EQ(frames_csv_header(), std::string(kHeader) + "\n"); }

TEST(RunRecorder, CsvHasOneRowPerFrameAndNode) {
  std::string csv = frames_csv_header();
  RunRecorder r({"a", "b"});
  feed_three_frames(r);
  csv += frames_csv(r.finalize());
  const std::vector<std::string> expected{
      kHeader,
      "0,a,1000000000,1000300000,1000600000,1002000000",
      "0,b,1000000000,1000500000,1000600000,1002030000",
      "1,a,1016666667,1017000000,1017466667,1018700000",
      "1,b,1016666667,1017400000,1017466667,",  // swapped, never presented: empty cell
      "2,a,1033333333,1033500000,1033733333,1035070000",
      "2,b,1033333333,1033700000,1033733333,1035000000",
  };
  EXPECT_EQ(lines_of(csv), expected);
  EXPECT_EQ(r.totals().frames_finalized, 3u);
}

TEST(RunRecorder, FinalizeBeforeStreamsOnlyOlderFrames) {
  std::string csv = frames_csv_header();
  RunRecorder r({"a", "b"});
  feed_three_frames(r);
  csv += frames_csv(r.finalize(2));
  EXPECT_EQ(r.totals().frames_finalized, 2u);
  auto lines = lines_of(csv);
  ASSERT_EQ(lines.size(), 5u);  // header + frames 0 and 1
  EXPECT_EQ(lines.back().rfind("1,b,", 0), 0u) << lines.back();
  // Frame 1 had one present, so no skew: the last skew is still frame 0's.
  EXPECT_NEAR(r.totals().last_present_skew_us, 30.0, kTolUs);
  EXPECT_EQ(r.totals().frames_with_missing_node, 1u);

  csv += frames_csv(r.finalize(2));  // again: nothing new
  EXPECT_EQ(lines_of(csv).size(), 5u);

  csv += frames_csv(r.finalize());
  EXPECT_EQ(r.totals().frames_finalized, 3u);
  EXPECT_EQ(lines_of(csv).size(), 7u);
  EXPECT_NEAR(r.totals().last_present_skew_us, 70.0, kTolUs);
}

TEST(RunRecorder, ReportSummarizesTheFrames) {
  RunRecorder r({"a", "b"});
  feed_three_frames(r);
  (void)r.finalize();
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.frames(), 3u);
  EXPECT_EQ(rep.nodes_configured(), 2u);

  // Barrier rounds 600, 800, 400 µs: nearest-rank median 600, p99 800.
  const auto& round = rep.sync().barrier_round_us();
  EXPECT_EQ(round.count(), 3u);
  EXPECT_NEAR(round.median(), 600.0, kTolUs);
  EXPECT_NEAR(round.p99(), 800.0, kTolUs);
  EXPECT_NEAR(round.max(), 800.0, kTolUs);

  // Present skews 30 and 70 µs; frame 1 (only a presented) has none: median 30.
  const auto& skew = rep.sync().present_skew_us();
  EXPECT_EQ(skew.count(), 2u);
  EXPECT_NEAR(skew.median(), 30.0, kTolUs);
  EXPECT_NEAR(skew.p99(), 70.0, kTolUs);
  EXPECT_NEAR(skew.max(), 70.0, kTolUs);

  // Frame 1: b was told to swap and never presented.
  EXPECT_EQ(rep.sync().frames_with_missing_node(), 1u);
  EXPECT_EQ(rep.sync().frames_incoherent(), 1u);

  // Three frames begun over 33 333 333 ns: two periods, 60 Hz.
  EXPECT_NEAR(rep.sync().achieved_frame_rate(), 60.0, 1e-3);

  ASSERT_EQ(rep.nodes_size(), 2);
  const auto& a = rep.nodes(0);
  const auto& b = rep.nodes(1);
  EXPECT_EQ(a.id(), "a");
  EXPECT_EQ(b.id(), "b");
  EXPECT_EQ(a.frames_presented(), 3u);
  EXPECT_EQ(b.frames_presented(), 2u);
  EXPECT_EQ(a.frames_rendered(), 3u);
  EXPECT_EQ(b.frames_rendered(), 3u);
  EXPECT_EQ(a.joins(), 1u);
  EXPECT_EQ(b.joins(), 1u);
  // Render times a: 250, 300, 200 µs; b: 450, 500, 350 µs.
  EXPECT_EQ(a.render_us().count(), 3u);
  EXPECT_NEAR(a.render_us().median(), 250.0, kTolUs);
  EXPECT_NEAR(a.render_us().max(), 300.0, kTolUs);
  EXPECT_NEAR(b.render_us().median(), 450.0, kTolUs);
  EXPECT_NEAR(b.render_us().max(), 500.0, kTolUs);
}

// The FrameBegin's size each frame, as the frame loop gives it; a frame begun
// without one (0) is not counted.
TEST(RunRecorder, FrameBeginBytesAreSummarized) {
  RunRecorder r({"a"});
  r.frame_begun(0, 1'000'000'000, {0}, 1000);
  r.frame_begun(1, 1'016'666'667, {0}, 3000);
  r.frame_begun(2, 1'033'333'333, {0}, 2000);
  r.frame_begun(3, 1'050'000'000, {0});
  (void)r.finalize();
  const report::RunReport rep = r.report();
  const report::Distribution& bytes = rep.frame_begin_bytes();
  EXPECT_EQ(bytes.count(), 3u);
  EXPECT_EQ(bytes.median(), 2000.0);
  EXPECT_EQ(bytes.max(), 3000.0);
  EXPECT_FALSE(RunRecorder({"a"}).report().has_frame_begin_bytes());
}

TEST(RunRecorder, ReportCoversOnlyFinalizedFrames) {
  RunRecorder r({"a", "b"});
  feed_three_frames(r);
  (void)r.finalize(1);  // frame 0 only
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.frames(), 1u);
  EXPECT_EQ(rep.sync().present_skew_us().count(), 1u);
  EXPECT_NEAR(rep.sync().present_skew_us().median(), 30.0, kTolUs);
  EXPECT_EQ(rep.sync().frames_with_missing_node(), 0u);
  EXPECT_EQ(rep.sync().frames_incoherent(), 0u);
}

TEST(RunRecorder, NodeNotBegunHasNoRowAndCountsAsMissing) {
  std::string csv = frames_csv_header();
  RunRecorder r({"a", "b"});
  r.frame_begun(5, 2'000'000'000, {0});  // b is not connected
  r.ready(5, 0, 2'000'100'000, 90'000);
  r.swapped(5, 2'000'150'000, {0});
  r.presented(5, 0, 2'001'000'000, 5);
  csv += frames_csv(r.finalize());
  const std::vector<std::string> expected{kHeader, "5,a,2000000000,2000100000,2000150000,2001000000"};
  EXPECT_EQ(lines_of(csv), expected);
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.sync().frames_with_missing_node(), 1u);
  EXPECT_EQ(rep.sync().frames_incoherent(), 0u);  // b was never told to swap
  EXPECT_EQ(rep.nodes(1).frames_presented(), 0u);
}

TEST(RunRecorder, NodeThatMissedTheBarrierHasEmptyCells) {
  std::string csv = frames_csv_header();
  RunRecorder r({"a", "b"});
  r.frame_begun(9, 3'000'000'000, {0, 1});
  r.ready(9, 0, 3'000'100'000, 90'000);
  r.node_event(1, NodeEvent::missed_barrier);
  r.swapped(9, 3'500'000'000, {0});     // swapped without b
  r.presented(9, 1, 3'500'900'000, 9);  // b was not told to swap: ignored
  r.presented(9, 0, 3'501'000'000, 9);
  csv += frames_csv(r.finalize());
  const std::vector<std::string> expected{kHeader, "9,a,3000000000,3000100000,3500000000,3501000000",
                                          "9,b,3000000000,,,"};
  EXPECT_EQ(lines_of(csv), expected);
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.nodes(1).barrier_misses(), 1u);
  EXPECT_EQ(rep.nodes(1).frames_presented(), 0u);
  EXPECT_EQ(rep.nodes(1).frames_rendered(), 0u);
  EXPECT_EQ(rep.sync().frames_with_missing_node(), 1u);
  EXPECT_EQ(rep.sync().frames_incoherent(), 0u);
  EXPECT_NEAR(rep.sync().barrier_round_us().median(), 500'000.0, kTolUs);
}

TEST(RunRecorder, DuplicateAndUnknownEventsAreIgnored) {
  RunRecorder r({"a"});
  r.frame_begun(1, 1'000, {0});
  r.ready(1, 0, 2'000, 500);
  r.ready(1, 0, 2'500, 700);  // duplicate FrameReady
  r.ready(8, 0, 2'600, 700);  // unknown frame
  r.swapped(1, 3'000, {0});
  r.presented(1, 0, 4'000, 1);
  r.presented(1, 0, 4'500, 1);  // duplicate Presented
  r.presented(8, 0, 4'600, 8);  // unknown frame
  r.node_event(0, NodeEvent::hash_mismatch);
  r.node_event(0, NodeEvent::hash_mismatch);
  (void)r.finalize();
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.nodes(0).frames_rendered(), 1u);
  EXPECT_EQ(rep.nodes(0).frames_presented(), 1u);
  EXPECT_NEAR(rep.nodes(0).render_us().median(), 0.5, kTolUs);
  EXPECT_EQ(rep.nodes(0).hash_mismatches(), 2u);
  EXPECT_EQ(rep.sync().present_skew_us().count(), 0u) << "one node has no skew";
  EXPECT_EQ(rep.sync().frames_with_missing_node(), 0u);
}

// --- what a node reports is bounded at the recorder's door

constexpr clock::Nanos kHuge = std::numeric_limits<clock::Nanos>::max();
constexpr clock::Nanos kHugeNegative = std::numeric_limits<clock::Nanos>::min();

TEST(RunRecorder, AbsurdRenderTimesAreCountedNotRecorded) {
  RunRecorder r({"a", "b", "c"});
  r.frame_begun(1, 1'000'000'000, {0, 1, 2});
  r.ready(1, 0, 1'000'100'000, kHuge, wire::DRAWN_KEY);
  r.ready(1, 1, 1'000'100'000, -5);
  r.ready(1, 2, 1'000'100'000, kLongestRender);  // a minute: slow, not absurd
  (void)r.finalize();
  const report::RunReport rep = r.report();
  for (int n = 0; n < 2; ++n) {
    EXPECT_EQ(rep.nodes(n).frames_rendered(), 1u) << "it did say it was ready";
    EXPECT_EQ(rep.nodes(n).render_us().count(), 0u);
    EXPECT_EQ(rep.nodes(n).out_of_range(), 1u);
    EXPECT_EQ(r.node_counts(static_cast<std::size_t>(n)).render_us_sum, 0.0);
    EXPECT_EQ(r.node_counts(static_cast<std::size_t>(n)).render_times, 0u);
    EXPECT_LT(r.recent().back().render_us[static_cast<std::size_t>(n)], 0.0F) << "charted as not rendered";
  }
  EXPECT_EQ(rep.nodes(0).up_conversion().key_frames_total(), 1u) << "still a key frame";
  EXPECT_EQ(rep.nodes(0).up_conversion().key_render_us().count(), 0u);
  EXPECT_EQ(rep.nodes(2).out_of_range(), 0u);
  EXPECT_NEAR(rep.nodes(2).render_us().max(), 60e6, kTolUs);
  EXPECT_EQ(r.node_counts(2).render_times, 1u);
}

TEST(RunRecorder, PresentTimesFarFromTheSwapAreCountedNotRecorded) {
  std::string csv = frames_csv_header();
  RunRecorder r({"a", "b", "c", "d"});
  const clock::Nanos swap = 2'000'000'000;
  r.frame_begun(3, 1'990'000'000, {0, 1, 2, 3});
  r.swapped(3, swap, {0, 1, 2, 3});
  r.presented(3, 0, kHuge, 3);
  r.presented(3, 1, kHugeNegative, 3);
  r.presented(3, 2, swap + kFarthestPresent + 1, 3);
  r.presented(3, 3, swap - kFarthestPresent, 3);  // at the bound: recorded
  r.presented(3, 2, swap + 1'000'000, 3);         // then a plausible one: taken
  csv += frames_csv(r.finalize());
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.nodes(0).frames_presented(), 0u);
  EXPECT_EQ(rep.nodes(0).out_of_range(), 1u);
  EXPECT_EQ(rep.nodes(1).out_of_range(), 1u);
  EXPECT_EQ(rep.nodes(2).out_of_range(), 1u);
  EXPECT_EQ(rep.nodes(2).frames_presented(), 1u);
  EXPECT_EQ(rep.nodes(3).out_of_range(), 0u);
  // Skew between the two in bounds only: 61 s, not 2^64 ns.
  EXPECT_NEAR(rep.sync().present_skew_us().max(), 60e6 + 1e3, kTolUs);
  EXPECT_EQ(rep.sync().frames_incoherent(), 1u) << "a and b were told to swap and said nothing usable";
  const auto lines = lines_of(csv);
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[1], "3,a,1990000000,,2000000000,");
  EXPECT_EQ(lines[2], "3,b,1990000000,,2000000000,");
}

TEST(RunRecorder, ImplausibleClockEstimatesAreCountedAndThePreviousKept) {
  RunRecorder r({"a"});
  report::ClockReport good;
  good.set_offset_ns(-50'000'000);
  good.set_drift_ppm(12.5);
  good.set_round_trip_ns(8'000);
  good.set_error_bound_ns(4'000);
  r.clock_estimated(1, 0, good, std::nullopt);
  std::vector<std::pair<const char*, report::ClockReport>> bad;
  for (const double drift : {std::nan(""), std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(), 2e4, -1e4 - 1}) {
    bad.emplace_back("drift", good);
    bad.back().second.set_drift_ppm(drift);
  }
  bad.emplace_back("offset", good);
  bad.back().second.set_offset_ns(kHuge);
  bad.emplace_back("offset", good);
  bad.back().second.set_offset_ns(kHugeNegative);
  bad.emplace_back("round trip", good);
  bad.back().second.set_round_trip_ns(-1);
  bad.emplace_back("round trip", good);
  bad.back().second.set_round_trip_ns(kHuge);
  bad.emplace_back("error bound", good);
  bad.back().second.set_error_bound_ns(kHuge);
  for (const auto& [what, clock] : bad) {
    r.clock_estimated(1, 0, clock, std::nullopt);
    EXPECT_EQ(r.node_counts(0).clock.drift_ppm(), 12.5) << what;
    EXPECT_EQ(r.node_counts(0).clock.offset_ns(), -50'000'000) << what;
    EXPECT_EQ(r.node_counts(0).clock.round_trip_ns(), 8'000) << what;
    EXPECT_EQ(r.node_counts(0).clock.error_bound_ns(), 4'000) << what;
  }
  r.clock_estimated(1, 0, good, kHugeNegative);  // the test hook's true error, too
  EXPECT_EQ(r.node_counts(0).out_of_range, bad.size() + 1);
  report::ClockReport next = good;
  next.set_drift_ppm(-kLargestDriftPpm);
  next.set_offset_ns(kLargestClockOffset);
  r.clock_estimated(1, 0, next, std::nullopt);
  EXPECT_EQ(r.node_counts(0).clock.drift_ppm(), -kLargestDriftPpm) << "at the bounds: taken";
  EXPECT_EQ(r.report().nodes(0).out_of_range(), bad.size() + 1);
}

TEST(RunRecorder, EmptyRunReport) {
  RunRecorder r({"a", "b", "c"});
  (void)r.finalize();
  const report::RunReport rep = r.report();
  EXPECT_EQ(rep.frames(), 0u);
  EXPECT_EQ(rep.nodes_configured(), 3u);
  EXPECT_EQ(rep.nodes_size(), 3);
  EXPECT_EQ(rep.sync().barrier_round_us().count(), 0u);
  EXPECT_DOUBLE_EQ(rep.sync().achieved_frame_rate(), 0.0);
}

}  // namespace
}  // namespace optique::master
