#include "master/status/status_metrics.h"

#include <fmt/format.h>

#include <cmath>
#include <utility>
#include <vector>

namespace optique::master {
namespace {

using Labels = std::vector<std::pair<std::string, std::string>>;

// Label values escape backslash, double quote and newline.
std::string escaped(const std::string& value) {
  std::string out;
  out.reserve(value.size());
  for (const char c : value) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '"') {
      out += "\\\"";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

class Writer {
 public:
  void family(const char* name, const char* type, const char* help) {
    text_ += fmt::format("# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
  }
  void sample(const std::string& name, const Labels& labels, double value) {
    text_ += name;
    if (!labels.empty()) {
      text_ += '{';
      for (std::size_t i = 0; i < labels.size(); ++i) {
        text_ += fmt::format("{}{}=\"{}\"", i == 0 ? "" : ",", labels[i].first, escaped(labels[i].second));
      }
      text_ += '}';
    }
    if (std::isnan(value)) {
      text_ += " NaN\n";
    } else if (std::isinf(value)) {
      text_ += value > 0 ? " +Inf\n" : " -Inf\n";
    } else {
      text_ += fmt::format(" {}\n", value);
    }
  }
  void sample(const std::string& name, const Labels& labels, std::uint64_t value) {
    sample(name, labels, static_cast<double>(value));
  }
  // A family with one sample and no labels.
  template <class T>
  void single(const char* name, const char* type, const char* help, T value) {
    family(name, type, help);
    sample(name, {}, value);
  }
  // A summary: quantiles (recent), then _sum and _count.
  void summary(const std::string& name, const Labels& labels, const std::optional<double>& median,
               const std::optional<double>& p99, double sum, std::uint64_t count) {
    const double nan = std::nan("");
    Labels q = labels;
    q.emplace_back("quantile", "0.5");
    sample(name, q, median.value_or(nan));
    q.back().second = "0.99";
    sample(name, q, p99.value_or(nan));
    sample(name + "_sum", labels, sum);
    sample(name + "_count", labels, count);
  }
  [[nodiscard]] std::string take() { return std::move(text_); }

 private:
  std::string text_;
};

// Divided, not multiplied by the inverse: 40 µs reads 4e-05 s, not 3.9999999999999996e-05.
std::optional<double> in_seconds(const std::optional<double>& value, double per_second) {
  return value ? std::optional(*value / per_second) : std::nullopt;
}

}  // namespace

std::string status_metrics(const LiveStatus& s) {
  Writer w;
  w.family("optique_state", "gauge", "The run's state: 1 for the one it is in.");
  for (const char* state : {"starting", "running", "paused", "stopping", "done"}) {
    w.sample("optique_state", {{"state", state}}, s.state == state ? 1.0 : 0.0);
  }
  w.single("optique_uptime_seconds", "gauge", "Seconds since the master started.", s.uptime_s);
  w.single("optique_frames_begun_total", "counter", "Frames begun (sent to the nodes).", s.next_frame);
  w.single("optique_frame_rate_target_hertz", "gauge", "The configured frame rate.", s.target_rate_hz);
  w.single("optique_frame_rate_hertz", "gauge", "Frames begun per second over the last two seconds.", s.frame_rate_hz);
  w.family("optique_present_skew_seconds", "summary",
           "Spread of the nodes' present times of a frame; quantiles over the recent frames.");
  w.summary("optique_present_skew_seconds", {}, in_seconds(s.skew_us_median, 1e6), in_seconds(s.skew_us_p99, 1e6),
            s.skew_us_sum / 1e6, s.skew_count);
  w.single("optique_frames_with_missing_node_total", "counter", "Frames that a node up did not present.",
           s.frames_with_missing_node);
  w.single("optique_frames_incoherent_total", "counter",
           "Frames some projector showed other content for, or never showed.", s.frames_incoherent);
  w.single("optique_frames_dropped_total", "counter", "Frames dropped everywhere (straggler policy drop).",
           s.frames_dropped);
  w.single("optique_nodes_up", "gauge", "Nodes in the frame loop.", static_cast<std::uint64_t>(s.nodes_up));
  w.single("optique_projectors", "gauge", "Projectors in the installation.",
           static_cast<std::uint64_t>(s.nodes.size()));

  const auto per_node = [&](const char* name, const char* type, const char* help, auto value) {
    w.family(name, type, help);
    for (const LiveNode& node : s.nodes) w.sample(name, {{"projector", node.id}}, value(node));
  };
  per_node("optique_node_up", "gauge", "1 while the projector's node is in the frame loop.",
           [](const LiveNode& n) { return n.link == NodeLink::up || n.link == NodeLink::behind ? 1.0 : 0.0; });
  per_node("optique_node_frames_rendered_total", "counter", "Frames the node rendered.",
           [](const LiveNode& n) { return n.counts.rendered; });
  per_node("optique_node_frames_presented_total", "counter", "Frames the node presented.",
           [](const LiveNode& n) { return n.counts.presented; });
  per_node("optique_node_barrier_misses_total", "counter", "Frames the node was not ready for in time.",
           [](const LiveNode& n) { return n.counts.barrier_misses; });
  per_node("optique_node_hash_mismatches_total", "counter", "Frames whose scene state differed on the node.",
           [](const LiveNode& n) { return n.counts.hash_mismatches; });
  per_node("optique_node_joins_total", "counter", "Times the node joined the frame loop.",
           [](const LiveNode& n) { return n.counts.joins; });
  per_node("optique_node_out_of_range_total", "counter",
           "Values the node reported beyond any plausible bound (render, present or clock), not recorded.",
           [](const LiveNode& n) { return n.counts.out_of_range; });
  w.family("optique_node_render_seconds", "summary",
           "The node's render time of a frame; quantiles over the recent frames.");
  for (const LiveNode& node : s.nodes) {
    w.summary("optique_node_render_seconds", {{"projector", node.id}}, in_seconds(node.render_ms_median, 1e3),
              in_seconds(node.render_ms_p99, 1e3), node.counts.render_us_sum / 1e6, node.counts.render_times);
  }
  per_node("optique_node_clock_offset_seconds", "gauge", "The node's latest estimate of master minus node clock.",
           [](const LiveNode& n) { return static_cast<double>(n.counts.clock.offset_ns()) / 1e9; });
  per_node("optique_node_clock_error_bound_seconds", "gauge", "Bound on the error of that estimate.",
           [](const LiveNode& n) { return static_cast<double>(n.counts.clock.error_bound_ns()) / 1e9; });
  per_node("optique_node_clock_round_trip_seconds", "gauge", "Round trip of the node's best recent ping.",
           [](const LiveNode& n) { return static_cast<double>(n.counts.clock.round_trip_ns()) / 1e9; });

  if (s.tracking) {
    const report::TrackingReport& t = *s.tracking;
    w.family("optique_tracker_state", "gauge", "The head tracker's state: 1 for the one it is in.");
    for (const char* state : {"waiting", "tracking", "holding", "easing", "resting"}) {
      w.sample("optique_tracker_state", {{"state", state}}, t.state() == state ? 1.0 : 0.0);
    }
    w.single("optique_tracker_datagrams_total", "counter", "Datagrams received from the tracker.", t.datagrams());
    w.single("optique_tracker_samples_total", "counter", "Head samples taken.", t.samples());
    w.family("optique_tracker_ignored_total", "counter", "Datagrams or samples ignored, by reason.");
    w.sample("optique_tracker_ignored_total", {{"reason", "malformed"}}, t.malformed());
    w.sample("optique_tracker_ignored_total", {{"reason", "without_body"}}, t.without_body());
    w.sample("optique_tracker_ignored_total", {{"reason", "backwards"}}, t.backwards());
    w.sample("optique_tracker_ignored_total", {{"reason", "flood"}}, t.flood());
    w.sample("optique_tracker_ignored_total", {{"reason", "other_sender"}}, t.other_sender());
    w.single("optique_tracker_losses_total", "counter", "Times the tracker was lost.", t.losses());
    w.single("optique_tracker_lost_seconds_total", "counter", "Seconds the tracker was lost.", t.lost_seconds());
  }
  w.single("optique_status_connections", "gauge", "Open connections to this status server.", s.clients.open);
  w.single("optique_status_requests_total", "counter", "Requests this status server answered.", s.clients.requests);
  w.single("optique_status_refused_total", "counter",
           "Connections this status server closed: busy, too many from one address, too slow, too large, not HTTP "
           "or an event stream behind.",
           s.clients.refused);
  return w.take();
}

}  // namespace optique::master
