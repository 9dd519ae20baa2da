#include "tracking/head_tracker.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "tracking/dtrack.h"

namespace optique::tracking {
namespace {

using clock::nanos;

// The reader's period in datagram(): a 60 Hz frame.
constexpr Nanos kDefaultReadPeriod = clock::kNanosPerSecond / 60;

Nanos seconds_to_nanos(double seconds) {
  return static_cast<Nanos>(std::llround(seconds * static_cast<double>(clock::kNanosPerSecond)));
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
    : settings_(settings),
      rest_turn_(rest_turn),
      predictor_(settings.prediction, settings.smoothing),
      reader_(settings, kDefaultReadPeriod),
      sequence_(nanos(settings.lost_after)) {}

std::optional<std::string> HeadTracker::datagram(std::string_view bytes, Nanos arrival, std::string_view sender) {
  TrackerInput read;
  reader_.read(bytes, arrival, sender, read);
  std::vector<std::string> said;
  input(std::move(read), said);
  if (said.empty()) return std::nullopt;
  std::string joined;
  for (const std::string& text : said) joined += (joined.empty() ? "" : "; ") + text;
  return joined;
}

void HeadTracker::input(TrackerInput input, std::vector<std::string>& said) {
  counts_ += input.counted;
  for (std::string& text : input.said) said.push_back(std::move(text));
  for (const DTrackSample& sample : input.samples) take_dtrack(sample, said);
}

void HeadTracker::take_dtrack(const DTrackSample& sample, std::vector<std::string>& said) {
  const Order order = sequence_.order(sample);
  const Nanos shows = sample.arrival - seconds_to_nanos(sample.latency) - nanos(settings_.latency);
  const bool restarted = order == Order::restart;
  if (order == Order::outside || (!restarted && !predictor_.empty() && shows <= predictor_.newest_time())) {
    ++counts_.backwards;
    say_once(said_backwards_,
             "tracker: ignored a frame out of the tracker's sequence (older than the last one taken, "
             "or further ahead than the time since could bring)",
             said);
    return;
  }
  if (!restarted && !predictor_.empty() && shows - predictor_.newest_time() < kLeastSampleInterval) {
    ++counts_.flood;
    say_once(said_flood_, "tracker: a frame less than 1 ms after the last one taken; dropped", said);
    return;
  }
  if (restarted) {
    predictor_.reset();  // what it knew was of the sequence before
    said.push_back("tracker: its frame counter (or clock) started again, " + std::to_string(kRestartDatagrams) +
                   " frames in a row; following it");
  }
  sequence_.taken(sample);
  take(shows, sample.arrival, sample.position * 0.001, glm::quat_cast(sample.rotation));
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

InstallationPose to_installation(const config::Tracking& settings, const glm::dvec3& position,
                                 const glm::dquat& orientation) {
  const glm::dmat3& axes = settings.tracker_axes;
  return {axes * position + settings.tracker_origin, glm::normalize(glm::quat_cast(axes) * orientation)};
}

void HeadTracker::take(Nanos time, Nanos arrival, const glm::dvec3& position, const glm::dquat& orientation) {
  const auto [body, turn] = to_installation(settings_, position, orientation);
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

void HeadTracker::notice_start(Nanos now, std::vector<std::string>& said) {
  if (settings_.source != config::TrackingSource::dtrack) return;
  if (!first_now_) first_now_ = now;
  if (!last_arrival_ && !said_quiet_start_ && now - *first_now_ >= kQuietStart) {
    said_quiet_start_ = true;
    said.push_back("tracker: no sample in " + std::to_string(kQuietStart / clock::kNanosPerSecond) +
                   " s; listening for DTrack's output (body " + std::to_string(settings_.body) + ") on " +
                   settings_.listen + " port " + std::to_string(settings_.port) + " (UDP)" +
                   (settings_.from.empty() ? "" : " from " + settings_.from) +
                   "; the eyes rest where the config puts them");
  }
  if (last_arrival_ && said_quiet_start_ && !said_first_sample_) {
    said_first_sample_ = true;
    said.push_back("tracker: the first sample came " +
                   std::to_string((*last_arrival_ - *first_now_) / clock::kNanosPerMilli) +
                   " ms after the first frame; tracking");
  }
}

void HeadTracker::notice(Nanos now, std::vector<std::string>& said) {
  const Nanos lost_after = nanos(settings_.lost_after);
  const std::optional<Nanos> before = last_now_;
  last_now_ = now;
  notice_start(now, said);
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
