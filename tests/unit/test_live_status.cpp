// The live status: what the recent frames say (rate, skew, frame time, render
// times, the chart), and how it reads as JSON and as Prometheus text.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <regex>
#include <sstream>

#include "master/live_status.h"
#include "master/status/status_json.h"
#include "master/status/status_metrics.h"

namespace optique::master {
namespace {

constexpr clock::Nanos kMs = clock::kNanosPerMilli;

// `count` frames 20 ms apart from t = 1 s; skew 10·i µs; node 0 renders in
// (i + 1) ms, node 1 renders none.
std::deque<RecentFrame> frames(std::size_t count) {
  std::deque<RecentFrame> recent;
  for (std::size_t i = 0; i < count; ++i) {
    RecentFrame f;
    f.id = 100 + i;
    f.begin_sent = 1000 * kMs + static_cast<clock::Nanos>(i) * 20 * kMs;
    f.skew_us = 10.0 * static_cast<double>(i);
    f.render_us = {1000.0F * static_cast<float>(i + 1), -1.0F};
    recent.push_back(f);
  }
  return recent;
}

LiveStatus two_nodes() {
  LiveStatus s;
  s.state = "running";
  s.target_rate_hz = 60;
  s.nodes.resize(2);
  s.nodes[0].id = "left";
  s.nodes[0].link = NodeLink::up;
  s.nodes[1].id = "right \"quoted\"";
  s.nodes[1].link = NodeLink::gone;
  return s;
}

TEST(LiveStatus, RecentFramesGiveRateSkewAndRenderTimes) {
  LiveStatus s = two_nodes();
  const std::deque<RecentFrame> recent = frames(101);  // 1.0 s to 3.0 s
  summarize_recent(recent, 3000 * kMs, s);
  // The last two seconds hold frames at 1.0 … 3.0 s: 101 frames, 100 intervals of 20 ms.
  EXPECT_NEAR(s.frame_rate_hz, 50.0, 1e-9);
  EXPECT_DOUBLE_EQ(*s.frame_ms_median, 20.0);
  EXPECT_DOUBLE_EQ(*s.skew_us_median, 500.0);
  EXPECT_DOUBLE_EQ(*s.skew_us_p99, 990.0);
  EXPECT_DOUBLE_EQ(*s.nodes[0].render_ms_median, 51.0);
  EXPECT_FALSE(s.nodes[1].render_ms_median) << "a node that rendered none has no render time";
  ASSERT_EQ(s.history.size(), 101u);
  EXPECT_EQ(s.history.front().frame, 100u);
  EXPECT_DOUBLE_EQ(*s.history.front().frame_ms, 20.0);
  EXPECT_FALSE(s.history.back().frame_ms) << "the last frame's time is not known yet";
}

TEST(LiveStatus, OnlyTheLastTwoSecondsCountForTheRate) {
  LiveStatus s = two_nodes();
  summarize_recent(frames(101), 4000 * kMs, s);  // frames at 2.0 … 3.0 s are within two seconds
  EXPECT_NEAR(s.frame_rate_hz, 50.0, 1e-9);
  LiveStatus paused = two_nodes();
  summarize_recent(frames(101), 60'000 * kMs, paused);
  EXPECT_EQ(paused.frame_rate_hz, 0.0) << "no frame begun for a while: paused, or stuck";
  EXPECT_TRUE(paused.skew_us_median) << "the recent frames still say how they went";
}

TEST(LiveStatus, TheChartShowsTheLastFramesOnly) {
  LiveStatus s = two_nodes();
  summarize_recent(frames(kRecentFrames), 20'000 * kMs, s);
  ASSERT_EQ(s.history.size(), kChartFrames);
  EXPECT_EQ(s.history.back().frame, 100 + kRecentFrames - 1);
}

TEST(LiveStatus, JsonHasEveryFieldTheNodesAndTheChart) {
  LiveStatus s = two_nodes();
  summarize_recent(frames(10), 1200 * kMs, s);
  s.warnings.push_back({"12:00:00", "node 'left' was late \xff"});
  const auto doc = nlohmann::json::parse(status_json(s));
  EXPECT_EQ(doc["state"], "running");
  ASSERT_EQ(doc["nodes"].size(), 2u);
  EXPECT_EQ(doc["nodes"][0]["state"], "up");
  EXPECT_EQ(doc["nodes"][1]["state"], "gone");
  EXPECT_TRUE(doc["nodes"][1]["render_ms"]["median"].is_null());
  EXPECT_EQ(doc["history"]["frame"].size(), 10u);
  EXPECT_TRUE(doc["history"]["frame_ms"][9].is_null());
  EXPECT_TRUE(doc["tracking"].is_null());
  EXPECT_EQ(doc["warnings"][0]["time"], "12:00:00");
  EXPECT_EQ(status_json(s).find('\n'), std::string::npos) << "one line: one event of the stream";
}

// Every sample line is a name, optional labels and a value; every name has its
// HELP and TYPE first; counters end in _total.
TEST(LiveStatus, MetricsAreWellFormedPrometheusText) {
  LiveStatus s = two_nodes();
  summarize_recent(frames(10), 1200 * kMs, s);
  s.tracking = report::TrackingReport();
  s.tracking->set_state("tracking");
  const std::string text = status_metrics(s);
  const std::regex sample(R"(^([a-z_]+)(\{([a-z_]+="([^"\\]|\\.)*",?)+\})? (NaN|[-+0-9.e]+)$)");
  std::istringstream lines(text);
  std::string line;
  std::string typed;
  std::string type;
  std::size_t samples = 0;
  while (std::getline(lines, line)) {
    std::smatch m;
    if (line.rfind("# TYPE ", 0) == 0) {
      std::istringstream fields(line.substr(7));
      fields >> typed >> type;
      if (type == "counter") {
        EXPECT_TRUE(typed.ends_with("_total")) << typed;
      }
      continue;
    }
    if (line.rfind("# HELP ", 0) == 0) continue;
    ASSERT_TRUE(std::regex_match(line, m, sample)) << line;
    EXPECT_EQ(m[1].str().rfind(typed, 0), 0u) << m[1] << " under # TYPE " << typed;
    ++samples;
  }
  EXPECT_GT(samples, 40u);
  EXPECT_NE(text.find("optique_node_up{projector=\"left\"} 1\n"), std::string::npos);
  EXPECT_NE(text.find("optique_node_up{projector=\"right \\\"quoted\\\"\"} 0\n"), std::string::npos);
  EXPECT_NE(text.find("optique_state{state=\"running\"} 1\n"), std::string::npos);
  EXPECT_NE(text.find("optique_tracker_state{state=\"tracking\"} 1\n"), std::string::npos);
  EXPECT_NE(text.find("optique_present_skew_seconds{quantile=\"0.5\"} 4e-05\n"), std::string::npos) << text;
}

// A node that reports absurd numbers (an authenticated one, broken or hostile):
// nothing of its in /metrics or /status.json is infinite, huge or NaN (but a
// quantile with no sample, which Prometheus writes so).
TEST(LiveStatus, AbsurdReportsReachNeitherTheMetricsNorTheJson) {
  constexpr clock::Nanos kHuge = std::numeric_limits<clock::Nanos>::max();
  RunRecorder recorder({"left", "right"});
  recorder.frame_begun(1, 1000 * kMs, {0, 1});
  recorder.ready(1, 0, 1001 * kMs, kHuge);
  recorder.ready(1, 1, 1001 * kMs, 2 * kMs);
  recorder.swapped(1, 1002 * kMs, {0, 1});
  recorder.presented(1, 0, -kHuge, 1);
  recorder.presented(1, 1, 1010 * kMs, 1);
  report::ClockReport clock;
  clock.set_drift_ppm(std::numeric_limits<double>::quiet_NaN());
  clock.set_offset_ns(kHuge);
  clock.set_round_trip_ns(kHuge);
  clock.set_error_bound_ns(kHuge);
  recorder.clock_estimated(1, 0, clock, std::nullopt);
  clock.set_drift_ppm(std::numeric_limits<double>::infinity());
  recorder.clock_estimated(1, 1, clock, std::nullopt);
  (void)recorder.finalize();

  LiveStatus s = two_nodes();
  for (std::size_t n = 0; n < 2; ++n) s.nodes[n].counts = recorder.node_counts(n);
  summarize_recent(recorder.recent(), 1100 * kMs, s);

  const std::string text = status_metrics(s);
  std::istringstream lines(text);
  std::size_t node_samples = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("optique_node_", 0) != 0) continue;
    ++node_samples;
    const std::string value = line.substr(line.rfind(' ') + 1);
    if (value == "NaN") {
      EXPECT_NE(line.find("quantile="), std::string::npos) << "only a quantile with no sample: " << line;
      continue;
    }
    const double number = std::stod(value);
    EXPECT_TRUE(std::isfinite(number)) << line;
    EXPECT_LT(std::abs(number), 1e6) << line;
  }
  EXPECT_GT(node_samples, 20u);
  EXPECT_NE(text.find("optique_node_out_of_range_total{projector=\"left\"} 3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("optique_node_out_of_range_total{projector=\"right \\\"quoted\\\"\"} 1\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("optique_node_render_seconds_count{projector=\"left\"} 0\n"), std::string::npos) << text;

  // JSON has no NaN (nlohmann writes it null) and no infinity: look for huge numbers.
  const auto doc = nlohmann::json::parse(status_json(s));
  std::function<void(const nlohmann::json&, const std::string&)> walk = [&](const nlohmann::json& j,
                                                                            const std::string& at) {
    if (j.is_structured()) {
      for (auto it = j.begin(); it != j.end(); ++it) walk(*it, at + "/" + (j.is_object() ? it.key() : "[]"));
    } else if (j.is_number()) {
      EXPECT_TRUE(std::isfinite(j.get<double>())) << at;
      EXPECT_LT(std::abs(j.get<double>()), 1e7) << at;
    }
  };
  walk(doc, "");
  EXPECT_TRUE(doc["nodes"][0]["clock"]["drift_ppm"].is_number()) << doc["nodes"][0]["clock"];
  EXPECT_EQ(doc["nodes"][0]["out_of_range"], 3);
}

// Text from peers (a warning the log repeats, whose peer-given parts the logger
// has escaped already) and odd ids cannot break the JSON's one line or the
// metrics' lines.
TEST(LiveStatus, OddTextStaysInsideItsJsonStringAndItsMetricsLabel) {
  LiveStatus s = two_nodes();
  s.nodes[0].id = "new\nline \\ back";
  s.warnings.push_back({"12:00:00", "</script><script>alert(1)</script>\n\x1b[31m\xc3"});
  const std::string json_text = status_json(s);
  EXPECT_EQ(json_text.find('\n'), std::string::npos);
  EXPECT_EQ(json_text.find('\x1b'), std::string::npos);
  const auto doc = nlohmann::json::parse(json_text);
  EXPECT_EQ(doc["nodes"][0]["id"], "new\nline \\ back");
  EXPECT_EQ(doc["warnings"][0]["text"].get<std::string>().rfind("</script><script>alert(1)</script>\n\x1b[31m", 0), 0u);
  const std::string text = status_metrics(s);
  EXPECT_NE(text.find("optique_node_up{projector=\"new\\nline \\\\ back\"} 1\n"), std::string::npos) << text;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    EXPECT_TRUE(line.rfind("optique_", 0) == 0 || line.rfind("# ", 0) == 0) << "a line of its own: " << line;
  }
}

}  // namespace
}  // namespace optique::master

namespace optique::master {
namespace {

// Frames unevenly apart (10, 20, 30 … ms): the chart's frame time k is the time
// from frame k to frame k + 1, not a neighbour's; and /metrics gives a node's
// render time in seconds (51 ms → 0.051), its sum too.
TEST(LiveStatus, TheChartAndTheMetricsCarryEachFramesOwnTimes) {
  std::deque<RecentFrame> recent = frames(6);
  clock::Nanos at = 1000 * kMs;
  for (std::size_t i = 0; i < recent.size(); ++i) {
    recent[i].begin_sent = at;
    at += static_cast<clock::Nanos>(10 * (i + 1)) * kMs;
  }
  LiveStatus s = two_nodes();
  summarize_recent(recent, 1200 * kMs, s);
  ASSERT_EQ(s.history.size(), 6u);
  for (std::size_t i = 0; i + 1 < s.history.size(); ++i) {
    ASSERT_TRUE(s.history[i].frame_ms) << i;
    EXPECT_DOUBLE_EQ(*s.history[i].frame_ms, 10.0 * static_cast<double>(i + 1)) << "frame " << i;
  }

  LiveStatus many = two_nodes();
  summarize_recent(frames(101), 3000 * kMs, many);
  many.nodes[0].counts.render_us_sum = 2'500'000.0;
  many.nodes[0].counts.render_times = 50;
  const std::string text = status_metrics(many);
  EXPECT_NE(text.find("optique_node_render_seconds{projector=\"left\",quantile=\"0.5\"} 0.051\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("optique_node_render_seconds_sum{projector=\"left\"} 2.5\n"), std::string::npos) << text;
  EXPECT_NE(text.find("optique_node_render_seconds_count{projector=\"left\"} 50\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace optique::master
