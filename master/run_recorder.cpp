#include "master/run_recorder.h"

#include <algorithm>
#include <cmath>

#include "metrics/distribution.h"

namespace optique::master {
namespace {

bool within(clock::Nanos value, clock::Nanos low, clock::Nanos high) { return value >= low && value <= high; }

bool plausible(const report::ClockReport& clock, std::optional<clock::Nanos> true_error) {
  return std::isfinite(clock.drift_ppm()) && std::abs(clock.drift_ppm()) <= kLargestDriftPpm &&
         within(clock.offset_ns(), -kLargestClockOffset, kLargestClockOffset) &&
         within(clock.round_trip_ns(), 0, kLongestRoundTrip) && within(clock.error_bound_ns(), 0, kLongestRoundTrip) &&
         (!true_error || within(*true_error, -kLongestRoundTrip, kLongestRoundTrip));
}

}  // namespace

RunRecorder::RunRecorder(std::vector<std::string> node_ids) : ids_(std::move(node_ids)), totals_(ids_.size()) {}

RunRecorder::FrameRecord* RunRecorder::find(std::uint64_t frame) {
  for (auto& record : open_) {
    if (record.id == frame) return &record;
  }
  return nullptr;
}

void RunRecorder::frame_begun(std::uint64_t frame, clock::Nanos sent, const std::vector<std::size_t>& nodes,
                              std::size_t bytes) {
  FrameRecord record;
  record.id = frame;
  record.begin_sent = sent;
  record.nodes.resize(ids_.size());
  for (std::size_t n : nodes) record.nodes[n].begun = true;
  open_.push_back(std::move(record));
  if (first_begin_ == 0) first_begin_ = sent;
  last_begin_ = sent;
  if (bytes > 0) {
    frame_begin_bytes_.add(static_cast<double>(bytes));
    frame_state_bytes_.add(static_cast<double>(bytes + staged_bytes_));
  }
  staged_bytes_ = 0;
}

void RunRecorder::ready(std::uint64_t frame, std::size_t node, clock::Nanos received, clock::Nanos render_time,
                        wire::DrawnAs drawn_as) {
  FrameRecord* record = find(frame);
  if (record == nullptr || record->nodes[node].ready != 0) return;
  record->nodes[node].ready = received;
  NodeTotals& t = totals_[node];
  t.counts.rendered += 1;
  std::optional<double> us;
  if (within(render_time, 0, kLongestRender)) {
    us = static_cast<double>(render_time) / 1e3;
    t.render_us.add(*us);
    t.counts.render_us_sum += *us;
    t.counts.render_times += 1;
    record->nodes[node].render_us = static_cast<float>(*us);
  } else {
    t.counts.out_of_range += 1;
  }
  // A value this master does not know (a newer node) counts as a full frame.
  if (drawn_as == wire::DRAWN_FULL || !wire::DrawnAs_IsValid(drawn_as)) return;
  metrics::Reservoir& drawn_as_us = t.render_us_drawn_as[drawn_as];  // there even without a time: it up-converts
  if (us) drawn_as_us.add(*us);
  if (drawn_as == wire::DRAWN_KEY || drawn_as == wire::DRAWN_KEY_SHOWN) {
    t.key_frames_total += 1;
    if (t.key_frames.size() < kMostKeyFramesListed) t.key_frames.push_back(frame);
  } else {
    t.between += 1;
  }
}

void RunRecorder::swapped(std::uint64_t frame, clock::Nanos sent, const std::vector<std::size_t>& nodes) {
  FrameRecord* record = find(frame);
  if (record == nullptr) return;
  record->swap_sent = sent;
  for (std::size_t n : nodes) record->nodes[n].swapped = true;
  barrier_round_us_.add(static_cast<double>(sent - record->begin_sent) / 1e3);
}

void RunRecorder::presented(std::uint64_t frame, std::size_t node, clock::Nanos at, std::uint64_t content_frame) {
  FrameRecord* record = find(frame);
  if (record == nullptr || !record->nodes[node].swapped || record->nodes[node].presented != 0) return;
  // Compared so that nothing overflows: `at` may be any 64-bit number.
  if (at < record->swap_sent - kFarthestPresent || at > record->swap_sent + kFarthestPresent) {
    totals_[node].counts.out_of_range += 1;
    return;
  }
  record->nodes[node].presented = at;
  record->nodes[node].content_frame = content_frame;
  totals_[node].counts.presented += 1;
}

void RunRecorder::clock_estimated(std::uint64_t frame, std::size_t node, const report::ClockReport& latest,
                                  std::optional<clock::Nanos> true_error) {
  // The first two seconds are the estimator's to settle in (the bar is set after them).
  constexpr clock::Nanos kSettling = 2 * clock::kNanosPerSecond;
  NodeTotals& t = totals_[node];
  if (!plausible(latest, true_error)) {
    t.counts.out_of_range += 1;
    return;
  }
  t.counts.clock = latest;
  const FrameRecord* record = find(frame);
  if (true_error && record != nullptr && record->begin_sent - first_begin_ >= kSettling) {
    t.clock_true_error_us.add(std::abs(static_cast<double>(*true_error)) / 1e3);
  }
}

void RunRecorder::frame_dropped(std::uint64_t) { ++run_.frames_dropped; }

void RunRecorder::node_event(std::size_t node, NodeEvent event) {
  NodeCounts& counts = totals_[node].counts;
  switch (event) {
    case NodeEvent::joined:
      counts.joins += 1;
      break;
    case NodeEvent::missed_barrier:
      counts.barrier_misses += 1;
      break;
    case NodeEvent::hash_mismatch:
      counts.hash_mismatches += 1;
      break;
  }
}

void RunRecorder::finalize(const FrameRecord& record, std::vector<FrameRow>& rows) {
  clock::Nanos earliest = 0;
  clock::Nanos latest = 0;
  std::size_t presented = 0;
  bool incoherent = false;
  RecentFrame recent;
  recent.id = record.id;
  recent.begin_sent = record.begin_sent;
  recent.render_us.reserve(record.nodes.size());
  for (std::size_t n = 0; n < record.nodes.size(); ++n) {
    const NodeFrame& f = record.nodes[n];
    recent.render_us.push_back(f.render_us);
    if (f.presented != 0) {
      earliest = presented == 0 ? f.presented : std::min(earliest, f.presented);
      latest = presented == 0 ? f.presented : std::max(latest, f.presented);
      ++presented;
      if (f.content_frame != record.id) incoherent = true;  // showed another frame's content
    } else if (f.swapped) {
      incoherent = true;  // told to show this frame, never said it did
    }
    if (f.begun) {
      const auto given = [](clock::Nanos t) { return t != 0 ? std::optional(t) : std::nullopt; };
      rows.push_back({record.id, ids_[n], record.begin_sent, given(f.ready),
                      f.swapped ? std::optional(record.swap_sent) : std::nullopt, given(f.presented)});
    }
  }
  if (presented >= 2) {  // skew is between nodes: one node alone has none
    // In double: present times come from the network and may be anything.
    const double skew_us = (static_cast<double>(latest) - static_cast<double>(earliest)) / 1e3;
    present_skew_us_.add(skew_us);
    run_.last_present_skew_us = skew_us;
    run_.present_skew_us_sum += skew_us;
    run_.present_skew_count = present_skew_us_.count();
    recent.skew_us = skew_us;
  }
  recent_.push_back(std::move(recent));
  if (recent_.size() > kRecentFrames) recent_.pop_front();
  if (presented < record.nodes.size()) ++run_.frames_with_missing_node;
  if (presented == 0) ++run_.frames_shown_by_none;
  if (incoherent) ++run_.frames_incoherent;
  ++run_.frames_finalized;
}

std::vector<FrameRow> RunRecorder::finalize(std::optional<std::uint64_t> before) {
  std::vector<FrameRow> rows;
  while (!open_.empty() && (!before || open_.front().id < *before)) {
    finalize(open_.front(), rows);
    open_.pop_front();
  }
  return rows;
}

report::RunReport RunRecorder::report() const {
  report::RunReport r;
  r.set_frames(run_.frames_finalized);
  r.set_nodes_configured(static_cast<std::uint32_t>(ids_.size()));
  for (std::size_t n = 0; n < ids_.size(); ++n) {
    const NodeTotals& t = totals_[n];
    auto& node = *r.add_nodes();
    node.set_id(ids_[n]);
    node.set_frames_rendered(t.counts.rendered);
    node.set_frames_presented(t.counts.presented);
    *node.mutable_render_us() = t.render_us.summary();
    if (!t.render_us_drawn_as.empty()) {
      report::UpConversionReport& up = *node.mutable_up_conversion();
      for (std::uint64_t key : t.key_frames) up.add_key_frames(key);
      up.set_key_frames_total(t.key_frames_total);
      up.set_frames_between(t.between);
      const auto summary = [&](wire::DrawnAs drawn_as, report::Distribution* into) {
        const auto found = t.render_us_drawn_as.find(drawn_as);
        if (found != t.render_us_drawn_as.end()) *into = found->second.summary();
      };
      summary(wire::DRAWN_KEY, up.mutable_key_render_us());
      summary(wire::DRAWN_BETWEEN, up.mutable_between_render_us());
      summary(wire::DRAWN_BETWEEN_AND_KEY_AHEAD, up.mutable_between_and_ahead_render_us());
      summary(wire::DRAWN_KEY_SHOWN, up.mutable_shown_render_us());
    }
    node.set_barrier_misses(t.counts.barrier_misses);
    node.set_hash_mismatches(t.counts.hash_mismatches);
    node.set_joins(t.counts.joins);
    node.set_out_of_range(t.counts.out_of_range);
    *node.mutable_clock() = t.counts.clock;
    if (t.clock_true_error_us.count() > 0)
      *node.mutable_clock()->mutable_true_error_us() = t.clock_true_error_us.summary();
  }
  if (frame_begin_bytes_.count() > 0) *r.mutable_frame_begin_bytes() = frame_begin_bytes_.summary();
  if (frame_state_bytes_.count() > 0) *r.mutable_frame_state_bytes() = frame_state_bytes_.summary();
  auto& sync = *r.mutable_sync();
  *sync.mutable_barrier_round_us() = barrier_round_us_.summary();
  *sync.mutable_present_skew_us() = present_skew_us_.summary();
  sync.set_frames_with_missing_node(run_.frames_with_missing_node);
  sync.set_frames_incoherent(run_.frames_incoherent);
  sync.set_frames_dropped(run_.frames_dropped);
  sync.set_frames_shown_by_none(run_.frames_shown_by_none);
  if (run_.frames_finalized > 1 && last_begin_ > first_begin_) {
    sync.set_achieved_frame_rate(static_cast<double>(run_.frames_finalized - 1) * 1e9 /
                                 static_cast<double>(last_begin_ - first_begin_));
  }
  return r;
}

}  // namespace optique::master
