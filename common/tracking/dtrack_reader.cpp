#include "tracking/dtrack_reader.h"

#include <algorithm>
#include <cassert>

#include "tracking/dtrack.h"
#include "util/join.h"

namespace optique::tracking {

void TrackerInput::newest(FlystickSample sample) {
  std::erase_if(flysticks, [&](const FlystickSample& had) { return had.id == sample.id; });
  flysticks.push_back(std::move(sample));
}

DTrackReader::DTrackReader(const config::Tracking& settings, Nanos period)
    : body_(settings.body), from_(settings.from), period_(std::max<Nanos>(period, 1)) {}

void DTrackReader::enter_period(std::uint64_t period) {
  if (period == current_period_) return;
  senders_before_ = period == current_period_ + 1 ? senders_now_ : 0;
  current_period_ = period;
  senders_now_ = 0;
  spent_ = 0;
}

DTrackReader::Sender& DTrackReader::sender_at(std::string_view sender, Nanos arrival) {
  auto found = senders_.find(sender);
  if (found == senders_.end()) {
    if (senders_.size() >= kMostSenders) {
      senders_.erase(std::min_element(senders_.begin(), senders_.end(),
                                      [](const auto& a, const auto& b) { return a.second.heard < b.second.heard; }));
    }
    found = senders_.emplace(std::string(sender), Sender{}).first;
    found->second.period = current_period_ - 1;  // not yet heard in this one
  }
  Sender& s = found->second;
  s.heard = arrival;
  if (s.period != current_period_) {
    s.period = current_period_;
    s.spent = 0;
    ++senders_now_;
  }
  return s;
}

void DTrackReader::read(std::string_view bytes, Nanos arrival, std::string_view sender, TrackerInput& into) {
  TrackingCounts& counts = into.counted;
  ++counts.datagrams;
  if (!from_.empty() && sender != from_) {
    ++counts.other_sender;
    say_once(said_other_sender_,
             "tracker: ignored datagrams from " + std::string(sender) + ": viewer.tracking.from is " + from_,
             into.said);
    return;
  }
  enter_period(static_cast<std::uint64_t>(std::max<Nanos>(arrival, 0) / period_));
  Sender& s = sender_at(sender, arrival);
  const std::string who = sender.empty() ? std::string("one sender") : std::string(sender);
  if (s.last_read && arrival - *s.last_read < kFloodInterval) {
    ++counts.flood;
    say_once(said_flood_,
             "tracker: datagrams from " + who + " come faster than " +
                 std::to_string(clock::kNanosPerSecond / kFloodInterval) +
                 " a second; the extra ones are dropped unread",
             into.said);
    return;
  }
  // Every sender heard lately gets an equal share; none gets more than the budget left.
  const std::size_t cost = std::max(bytes.size(), kLeastDatagramCost);
  const std::size_t share = kReadBudgetBytes / std::max<std::size_t>({senders_now_, senders_before_, 1});
  if (s.spent + cost > share || spent_ + cost > kReadBudgetBytes) {
    ++counts.flood;
    say_once(said_budget_,
             "tracker: more to read than " + std::to_string(kReadBudgetBytes / 1024) + " KiB a frame (" +
                 std::to_string(std::max(senders_now_, senders_before_)) + " senders); a datagram of " +
                 std::to_string(bytes.size()) + " bytes from " + who + " dropped unread",
             into.said);
    return;
  }
  s.last_read = arrival;
  s.spent += cost;
  spent_ += cost;
  auto frame = parse_dtrack(bytes);
  if (!frame) {
    ++counts.malformed;
    say_once(said_malformed_, "tracker: ignored a datagram that is not DTrack's ASCII output: " + frame.error(),
             into.said);
    return;
  }
  const DTrackFrame& f = frame.value();
  // The flysticks first: a frame without the head still carries the wand.
  for (const DTrackFlystick& stick : f.flysticks) {
    into.newest({arrival, stick.body.id, stick.body.quality >= 0.0, stick.body.position, stick.body.rotation,
                 stick.buttons, stick.controllers});
  }
  const auto body = std::find_if(f.bodies.begin(), f.bodies.end(), [&](const DTrackBody& b) { return b.id == body_; });
  if (body == f.bodies.end()) {
    ++counts.without_body;
    const std::string seen = util::joined(f.bodies, [](const DTrackBody& b) { return std::to_string(b.id); });
    say_once(said_without_body_,
             "tracker: a frame without body " + std::to_string(body_) +
                 (seen.empty() ? " (no body tracked)" : " (bodies " + seen + ")"),
             into.said);
    return;
  }
  into.samples.push_back(
      {arrival, std::string(sender), f.frame, f.timestamp, f.latency.value_or(0.0), body->position, body->rotation});
}

}  // namespace optique::tracking
