#pragma once
// The receiving side of DTrack's output, without IO: which datagrams are read at
// all, parsed, and reduced to the configured body's sample and the flysticks', before the head
// tracker (tracking/head_tracker.h) decides what a sample means. The master runs
// it on its own receive thread, so that the frame loop never parses; tests feed
// it bytes and times.
//
// What it drops unread, and counts: datagrams not from viewer.tracking.from (if
// set), those that come sooner than kFloodInterval after the last one read from
// the same sender, and those over the read budget. The budget bounds the bytes
// parsed per period (the master's frame period) across every sender together, and
// shares them out: a sender may use its share of the budget (the budget over the
// senders heard in this period or the last), so a tracker's few kilobytes a frame
// are read however many hosts flood the port with large datagrams.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "clock/clock.h"
#include "config/tracking.h"
#include "tracking/counts.h"

namespace optique::tracking {

using clock::Nanos;

inline constexpr Nanos kFloodInterval = 500'000;  // 2 kHz: DTrack sends at most 300 frames a second
// The senders remembered for the flood rule and the budget; beyond these, the
// one heard from longest ago is forgotten.
inline constexpr std::size_t kMostSenders = 64;
// Bytes parsed per period, every sender together: a DTrack frame with every
// kind of output is a few kilobytes, and a tracker sends at most five in a
// 60 Hz frame.
inline constexpr std::size_t kReadBudgetBytes = 128 * 1024;
// What a datagram costs against the budget at least (a read and a scan,
// however short it is).
inline constexpr std::size_t kLeastDatagramCost = 512;

// The configured body in one datagram, as the tracker sent it.
struct DTrackSample {
  Nanos arrival = 0;  // master clock: when the kernel received it
  std::string sender;
  std::optional<std::uint64_t> frame;  // fr
  std::optional<double> timestamp;     // seconds (ts or ts2)
  double latency = 0.0;                // seconds, the tracker's own (ts2); 0 without
  glm::dvec3 position{0.0};            // millimetres, tracker space
  glm::dmat3 rotation{1.0};            // body → tracker space
};

// A flystick in one datagram (DTrack's 6df2), as the tracker sent it: its
// pose (none when the cameras do not see it), its buttons and joystick.
struct FlystickSample {
  Nanos arrival = 0;  // master clock
  std::uint32_t id = 0;
  bool seen = false;
  glm::dvec3 position{0.0};  // millimetres, tracker space
  glm::dmat3 rotation{1.0};  // flystick → tracker space
  std::vector<bool> buttons;
  std::vector<double> controllers;  // −1…1: the joystick's x is [0], y [1]

  friend bool operator==(const FlystickSample&, const FlystickSample&) = default;
};

// What the receiving side hands the tracker: the samples in the order they
// arrived, the newest of each flystick, what it dropped (counted), and what is
// worth a log line.
struct TrackerInput {
  std::vector<DTrackSample> samples;
  std::vector<FlystickSample> flysticks;  // by arrival of their newest; one per id
  TrackingCounts counted;
  std::vector<std::string> said;

  // Keeps `sample` as its flystick's newest (the one before it goes).
  void newest(FlystickSample sample);
  [[nodiscard]] bool empty() const {
    return samples.empty() && flysticks.empty() && said.empty() && counted == TrackingCounts{};
  }
};

class DTrackReader {
 public:
  // `period`: the span the read budget is for (the master's frame period).
  DTrackReader(const config::Tracking& settings, Nanos period);

  // A datagram that arrived at `arrival` (master clock) from `sender` (its
  // address): its sample, or what was wrong with it, into `into`. The first of
  // each kind of refusal is said; further ones are only counted.
  void read(std::string_view bytes, Nanos arrival, std::string_view sender, TrackerInput& into);

 private:
  struct Sender {
    Nanos heard = 0;
    std::optional<Nanos> last_read;
    std::uint64_t period = 0;  // of `spent`
    std::size_t spent = 0;     // bytes read in that period
  };
  // The sender's entry, made if new (forgetting the one heard from longest ago).
  Sender& sender_at(std::string_view sender, Nanos arrival);
  void enter_period(std::uint64_t period);

  std::uint32_t body_;
  std::string from_;
  Nanos period_;
  std::map<std::string, Sender, std::less<>> senders_;
  std::uint64_t current_period_ = 0;
  std::size_t spent_ = 0;           // bytes read in the current period, every sender
  std::size_t senders_now_ = 0;     // heard in the current period
  std::size_t senders_before_ = 0;  // heard in the one before
  bool said_malformed_ = false;
  bool said_without_body_ = false;
  bool said_flood_ = false;
  bool said_budget_ = false;
  bool said_other_sender_ = false;
};

}  // namespace optique::tracking
