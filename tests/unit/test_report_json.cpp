// run.json's text (master/report_json.h): counts are numbers, not Protobuf's
// quoted 64-bit integers, and the text reads back into the same report.

#include "master/report_json.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

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

}  // namespace
}  // namespace optique::master
