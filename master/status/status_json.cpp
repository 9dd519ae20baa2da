#include "master/status/status_json.h"

#include <nlohmann/json.hpp>

namespace optique::master {
namespace {

using nlohmann::json;

json maybe(const std::optional<double>& value) { return value ? json(*value) : json(nullptr); }

json tracking_json(const report::TrackingReport& t) {
  return {{"source", t.source()},
          {"prediction", t.prediction()},
          {"state", t.state()},
          {"datagrams", t.datagrams()},
          {"samples", t.samples()},
          {"malformed", t.malformed()},
          {"without_body", t.without_body()},
          {"backwards", t.backwards()},
          {"flood", t.flood()},
          {"other_sender", t.other_sender()},
          {"losses", t.losses()},
          {"lost_seconds", t.lost_seconds()}};
}

json node_json(const LiveNode& node) {
  const report::ClockReport& clock = node.counts.clock;
  return {{"id", node.id},
          {"state", std::string(to_string(node.link))},
          {"peer", node.peer},
          {"rendered", node.counts.rendered},
          {"presented", node.counts.presented},
          {"barrier_misses", node.counts.barrier_misses},
          {"hash_mismatches", node.counts.hash_mismatches},
          {"joins", node.counts.joins},
          {"out_of_range", node.counts.out_of_range},
          {"render_ms", {{"median", maybe(node.render_ms_median)}, {"p99", maybe(node.render_ms_p99)}}},
          {"clock",
           {{"offset_us", static_cast<double>(clock.offset_ns()) / 1e3},
            {"error_bound_us", static_cast<double>(clock.error_bound_ns()) / 1e3},
            {"round_trip_us", static_cast<double>(clock.round_trip_ns()) / 1e3},
            {"drift_ppm", clock.drift_ppm()}}}};
}

}  // namespace

std::string status_json(const LiveStatus& s) {
  json nodes = json::array();
  for (const LiveNode& node : s.nodes) nodes.push_back(node_json(node));
  json warnings = json::array();
  for (const LiveWarning& w : s.warnings) warnings.push_back({{"time", w.time}, {"text", w.text}});
  // The chart's series in columns: a few thousand numbers, not objects.
  json frames = json::array();
  json skews = json::array();
  json frame_ms = json::array();
  for (const LivePoint& p : s.history) {
    frames.push_back(p.frame);
    skews.push_back(maybe(p.skew_us));
    frame_ms.push_back(maybe(p.frame_ms));
  }
  const json doc = {
      {"state", s.state},
      {"config", s.config_file},
      {"uptime_s", s.uptime_s},
      {"frame", s.next_frame},
      {"frames_target", s.frames_target},
      {"target_rate_hz", s.target_rate_hz},
      {"frame_rate_hz", s.frame_rate_hz},
      {"frame_ms_median", maybe(s.frame_ms_median)},
      {"present_skew_us", {{"median", maybe(s.skew_us_median)}, {"p99", maybe(s.skew_us_p99)}}},
      {"frames",
       {{"finalized", s.frames_finalized},
        {"with_missing_node", s.frames_with_missing_node},
        {"incoherent", s.frames_incoherent},
        {"dropped", s.frames_dropped}}},
      {"nodes_up", s.nodes_up},
      {"projectors", s.nodes.size()},
      {"nodes", nodes},
      {"tracking", s.tracking ? tracking_json(*s.tracking) : json(nullptr)},
      {"warnings", warnings},
      {"history", {{"frame", frames}, {"present_skew_us", skews}, {"frame_ms", frame_ms}}},
      {"clients",
       {{"open", s.clients.open},
        {"streams", s.clients.streams},
        {"requests", s.clients.requests},
        {"refused", s.clients.refused}}},
  };
  // Invalid UTF-8 (a peer's or a log line's bytes) is replaced, never thrown on.
  return doc.dump(-1, ' ', false, json::error_handler_t::replace);
}

}  // namespace optique::master
