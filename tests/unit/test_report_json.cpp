// run.json's text (master/report_json.h): counts are numbers, not Protobuf's
// quoted 64-bit integers, and the text reads back into the same report.

#include "master/report_json.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>
#include <limits>

#include "master/run_recorder.h"

namespace optique::master {
namespace {

report::RunReport sample() {
  report::RunReport r;
  r.set_config_file("configs/powerwall-2x2.json");
  r.set_frames(300);
  r.set_frame_rate(60.0);
  r.set_nodes_configured(2);
  r.set_connections_refused(3);
  for (const char* id : {"left", "right"}) {
    report::NodeReport& node = *r.add_nodes();
    node.set_id(id);
    node.set_frames_rendered(300);
    node.set_frames_presented(299);
    node.set_hash_mismatches(2);
    node.mutable_clock()->set_offset_ns(-50'000'123'456);
    node.mutable_clock()->set_round_trip_ns(6'500);
    node.mutable_clock()->mutable_true_error_us()->set_count(180);
  }
  r.mutable_sync()->mutable_barrier_round_us()->set_count(300);
  r.mutable_sync()->mutable_barrier_round_us()->set_median(140.5);
  r.mutable_sync()->set_frames_with_missing_node(1);
  return r;
}

TEST(ReportJson, CountsAreNumbers) {
  const std::string text = report_json(sample());
  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_TRUE(json["frames"].is_number_unsigned()) << text;
  EXPECT_EQ(json["frames"].get<std::uint64_t>(), 300u);
  EXPECT_EQ(json["connections_refused"].get<std::uint64_t>(), 3u);
  EXPECT_EQ(json["nodes"][1]["hash_mismatches"].get<std::uint64_t>(), 2u);
  EXPECT_EQ(json["nodes"][0]["clock"]["offset_ns"].get<std::int64_t>(), -50'000'123'456);
  EXPECT_EQ(json["nodes"][0]["clock"]["true_error_us"]["count"].get<std::uint64_t>(), 180u);
  EXPECT_EQ(json["sync"]["barrier_round_us"]["count"].get<std::uint64_t>(), 300u);
  EXPECT_EQ(json["sync"]["frames_dropped"].get<std::uint64_t>(), 0u) << "zeros are written too";
  EXPECT_EQ(text.find("\"300\""), std::string::npos) << text;
  // Field names as in report.proto, in its order.
  EXPECT_LT(text.find("\"config_file\""), text.find("\"frames\""));
  EXPECT_LT(text.find("\"frames\""), text.find("\"sync\""));
}

TEST(ReportJson, ReadsBackIntoTheSameReport) {
  const report::RunReport written = sample();
  report::RunReport read;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(report_json(written), &read).ok());
  EXPECT_TRUE(google::protobuf::util::MessageDifferencer::Equals(written, read)) << read.DebugString();
}

// A node that reports absurd numbers: run.json holds no NaN, infinity or number
// near 2^63 from it (Protobuf would print "NaN" and 9223372036854775807), only
// the count of what was left out.
TEST(ReportJson, AbsurdReportsDoNotReachRunJson) {
  constexpr std::int64_t kHuge = std::numeric_limits<std::int64_t>::max();
  RunRecorder recorder({"a", "b"});
  recorder.frame_begun(1, 1'000'000'000, {0, 1});
  recorder.ready(1, 0, 1'000'100'000, kHuge);
  recorder.ready(1, 1, 1'000'100'000, 300'000);
  recorder.swapped(1, 1'000'200'000, {0, 1});
  recorder.presented(1, 0, -kHuge - 1, 1);
  recorder.presented(1, 1, 1'002'000'000, 1);
  report::ClockReport clock;
  clock.set_drift_ppm(std::numeric_limits<double>::quiet_NaN());
  clock.set_offset_ns(kHuge);
  recorder.clock_estimated(1, 0, clock, kHuge);
  (void)recorder.finalize();
  const std::string text = report_json(recorder.report());
  EXPECT_EQ(text.find("NaN"), std::string::npos) << text;
  EXPECT_EQ(text.find("Infinity"), std::string::npos) << text;
  const nlohmann::json json = nlohmann::json::parse(text);
  std::function<void(const nlohmann::json&, const std::string&)> walk = [&](const nlohmann::json& j,
                                                                            const std::string& at) {
    if (j.is_structured()) {
      for (auto it = j.begin(); it != j.end(); ++it) walk(*it, at + "/" + (j.is_object() ? it.key() : "[]"));
    } else if (j.is_number()) {
      EXPECT_LT(std::abs(j.get<double>()), 1e12) << at << " in " << text;
    }
  };
  walk(json, "");
  EXPECT_EQ(json["nodes"][0]["out_of_range"].get<std::uint64_t>(), 3u);
  EXPECT_EQ(json["nodes"][1]["out_of_range"].get<std::uint64_t>(), 0u);
}

}  // namespace
}  // namespace optique::master
