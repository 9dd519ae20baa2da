#include "tracking/head_tracker.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "tracking/dtrack.h"

namespace optique::tracking {
namespace {

// A frame counter this far back, or a timestamp this many seconds, is a
// tracker that started again, not an old datagram.
constexpr std::uint64_t kRestartFrames = 1000;
constexpr double kRestartSeconds = 10.0;
constexpr int kRestartAfter = 30;  // frames back in a row: half a second at 60 Hz

Nanos seconds_to_nanos(double seconds) {
  return static_cast<Nanos>(std::llround(seconds * static_cast<double>(clock::kNanosPerSecond)));
}

template <class Duration>
Nanos nanos(Duration d) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace

std::string_view to_string(TrackerState state) {
  switch (state) {
    case TrackerState::waiting:
      return "waiting";
    case TrackerState::tracking:
      return "tracking";
    case TrackerState::holding:
      return "holding";
    case TrackerState::easing:
      return "easing";
    case TrackerState::resting:
      break;
  }
  return "resting";
}

HeadTracker::HeadTracker(const config::Tracking& settings, const glm::dquat& rest_turn)
    : settings_(settings), rest_turn_(rest_turn), predictor_(settings.prediction, settings.smoothing) {}

std::optional<std::string> HeadTracker::datagram(std::string_view bytes, Nanos arrival, std::string_view sender) {
  ++counts_.datagrams;
  const auto once = [](bool& said, std::string text) -> std::optional<std::string> {
    if (said) return std::nullopt;
    said = true;
    return text + " (further ones are only counted)";
  };
  if (!settings_.from.empty() && sender != settings_.from) {
    ++counts_.other_sender;
    return once(said_other_sender_, "tracker: ignored datagrams from " + std::string(sender) +
                                        ": viewer.tracking.from is " + settings_.from);
  }
  auto last = last_read_.find(sender);
  if (last != last_read_.end() && arrival - last->second < kFloodInterval) {
    ++counts_.flood;
    return once(said_flood_, "tracker: datagrams from " +
                                 (sender.empty() ? std::string("one sender") : std::string(sender)) +
                                 " come faster than " + std::to_string(clock::kNanosPerSecond / kFloodInterval) +
                                 " a second; the extra ones are dropped unread");
  }
  if (last == last_read_.end()) {
    if (last_read_.size() >= kMostSenders) {
      last_read_.erase(std::min_element(last_read_.begin(), last_read_.end(),
                                        [](const auto& a, const auto& b) { return a.second < b.second; }));
    }
    last = last_read_.emplace(std::string(sender), arrival).first;
  }
  last->second = arrival;
  auto frame = parse_dtrack(bytes);
  if (!frame) {
    ++counts_.malformed;
    return once(said_malformed_, "tracker: ignored a datagram that is not DTrack's ASCII output: " + frame.error());
  }
  const DTrackFrame& f = frame.value();
  const auto body =
      std::find_if(f.bodies.begin(), f.bodies.end(), [&](const DTrackBody& b) { return b.id == settings_.body; });
  if (body == f.bodies.end()) {
    ++counts_.without_body;
    std::string seen;
    for (const DTrackBody& b : f.bodies) seen += (seen.empty() ? "" : ", ") + std::to_string(b.id);
    return once(said_without_body_, "tracker: a frame without body " + std::to_string(settings_.body) +
                                        (seen.empty() ? " (no body tracked)" : " (bodies " + seen + ")"));
  }
  // Order: by the frame counter, else the timestamp. Far back, or back frame
  // after frame for kRestartAfter frames, is a tracker that started again.
  bool restarted = false;
  bool older = false;
  if (f.frame && last_frame_) {
    older = *f.frame <= *last_frame_;
    restarted = older && *last_frame_ - *f.frame > kRestartFrames;
  } else if (f.timestamp && last_timestamp_) {
    older = *f.timestamp <= *last_timestamp_;
    restarted = older && *last_timestamp_ - *f.timestamp > kRestartSeconds;
  }
  backwards_in_a_row_ = older ? backwards_in_a_row_ + 1 : 0;
  restarted = restarted || backwards_in_a_row_ >= kRestartAfter;
  const Nanos shows = arrival - seconds_to_nanos(f.latency.value_or(0.0)) - nanos(settings_.latency);
  if (!restarted && (older || (!predictor_.empty() && shows <= predictor_.newest_time()))) {
    ++counts_.backwards;
    return once(said_backwards_, "tracker: ignored a frame older than the last one taken");
  }
  if (!restarted && !predictor_.empty() && shows - predictor_.newest_time() < kLeastSampleInterval) {
    ++counts_.flood;
    return once(said_flood_, "tracker: a frame less than 1 ms after the last one taken; dropped");
  }
  if (restarted) {
    predictor_.reset();
    backwards_in_a_row_ = 0;
  }
  last_frame_ = f.frame;
  last_timestamp_ = f.timestamp;
  const glm::dquat orientation = glm::quat_cast(body->rotation);
  take(shows, arrival, body->position * 0.001, orientation);
  if (restarted) return "tracker: its frame counter (or clock) started again; following it";
  return std::nullopt;
}

void HeadTracker::sample(Nanos time, const glm::dvec3& position, const glm::dquat& orientation) {
  ++counts_.datagrams;
  if (!predictor_.empty() && time <= predictor_.newest_time()) {
    ++counts_.backwards;
    return;
  }
  if (!predictor_.empty() && time - predictor_.newest_time() < kLeastSampleInterval) {
    ++counts_.flood;
    return;
  }
  take(time, time, position, orientation);
}

void HeadTracker::take(Nanos time, Nanos arrival, const glm::dvec3& position, const glm::dquat& orientation) {
  const glm::dmat3& axes = settings_.tracker_axes;
  const glm::dvec3 body = axes * position + settings_.tracker_origin;
  const glm::dquat turn = glm::normalize(glm::quat_cast(axes) * orientation);
  HeadPose pose;
  pose.position = body + turn * settings_.eye_offset;
  pose.orientation = turn;
  if (last_arrival_ && arrival - *last_arrival_ > nanos(settings_.lost_after)) {
    predictor_.reset();  // what it knew is stale
  }
  predictor_.add(time, pose);
  last_arrival_ = arrival;
  ++counts_.samples;
}

void HeadTracker::notice(Nanos now, std::vector<std::string>& said) {
  const Nanos lost_after = nanos(settings_.lost_after);
  const std::optional<Nanos> before = last_now_;
  last_now_ = now;
  if (!last_arrival_) return;
  const bool lost = now - *last_arrival_ > lost_after;
  // The time lost, counted from the moment the tracker was lost to now.
  const auto count_lost = [&] {
    counts_.lost_ns += std::max<Nanos>(0, now - std::max(before.value_or(now), *lost_since_));
  };
  if (!lost) {
    if (lost_since_) {
      count_lost();
      said.push_back("tracker: back after " + std::to_string((now - *lost_since_) / clock::kNanosPerMilli) + " ms");
      lost_since_.reset();
    }
    state_ = TrackerState::tracking;
    return;
  }
  if (!lost_since_) {
    lost_since_ = *last_arrival_ + lost_after;
    // Held where the eyes were shown as the tracker went quiet: no snap back.
    held_ = predictor_.predict(*lost_since_);
    ++counts_.losses;
    said.push_back("tracker: lost (no sample for " + std::to_string(settings_.lost_after.count()) +
                   " ms); holding the last pose for " + std::to_string(settings_.hold.count()) +
                   " ms, then easing to the viewer's eye over " + std::to_string(settings_.ease.count()) + " ms");
    counts_.lost_ns += now - *lost_since_;
  } else {
    count_lost();
  }
  const Nanos since = now - *lost_since_;
  const Nanos hold = nanos(settings_.hold);
  const Nanos ease = nanos(settings_.ease);
  state_ = since < hold ? TrackerState::holding : since < hold + ease ? TrackerState::easing : TrackerState::resting;
  eased_ = state_ == TrackerState::holding ? 0.0
           : ease > 0                      ? smoothstep(static_cast<double>(since - hold) / static_cast<double>(ease))
                                           : 1.0;
}

HeadAt HeadTracker::at(Nanos time, const glm::dvec3& rest) const {
  const HeadPose resting{rest, rest_turn_};
  switch (state_) {
    case TrackerState::waiting:
      return {resting, state_};
    case TrackerState::tracking:
      return {predictor_.predict(time), state_};
    case TrackerState::holding:
      return {held_, state_};
    case TrackerState::easing:
    case TrackerState::resting:
      break;
  }
  HeadPose out;
  out.position = glm::mix(held_.position, rest, eased_);
  out.orientation = glm::normalize(glm::slerp(held_.orientation, resting.orientation, eased_));
  return {out, state_};
}

glm::dquat turn_onto_x(const glm::dvec3& head_right) {
  const glm::dvec3 from = glm::normalize(head_right);
  const glm::dvec3 to{1.0, 0.0, 0.0};
  const double c = glm::dot(from, to);
  if (c < -1.0 + 1e-12) return glm::angleAxis(M_PI, glm::dvec3(0.0, 1.0, 0.0));  // half a turn about up
  const glm::dvec3 axis = glm::cross(from, to);
  // (1 + c, axis) normalized: half the angle between them.
  return glm::normalize(glm::dquat(1.0 + c, axis.x, axis.y, axis.z));
}

ReplayFeed::ReplayFeed(std::vector<ReplaySample> samples, Nanos start) : samples_(std::move(samples)), start_(start) {
  const double last = samples_.empty() ? 0.0 : samples_.back().time - samples_.front().time;
  const double interval =
      samples_.size() > 1 ? (samples_.back().time - samples_.front().time) / static_cast<double>(samples_.size() - 1)
                          : 0.0;
  period_ = seconds_to_nanos(last + interval);
}

void ReplayFeed::feed(Nanos now, HeadTracker& tracker) {
  const auto n = static_cast<std::uint64_t>(samples_.size());
  if (n == 0) return;
  assert(n == 1 || period_ >= kLeastSampleInterval);  // parse_replay: samples 1 ms apart at least
  while (true) {
    if (n == 1 && next_ >= 1) return;
    const std::uint64_t loop = next_ / n;
    const ReplaySample& s = samples_[next_ % n];
    const Nanos due = start_ + static_cast<Nanos>(loop) * period_ + seconds_to_nanos(s.time - samples_.front().time);
    if (due > now) return;
    tracker.sample(due, s.position, s.orientation);
    ++next_;
  }
}

}  // namespace optique::tracking
