#pragma once
// What the head tracker took and what it ignored, counted: for run.json, the
// operator's page and the metrics; the first of each kind said. The reader (tracking/dtrack_reader.h) counts
// what it drops before the tracker sees it; the tracker adds those to its own.

#include <cstdint>
#include <string>
#include <vector>

#include "clock/clock.h"

namespace optique::tracking {

struct TrackingCounts {
  std::uint64_t datagrams = 0;     // received (flood included)
  std::uint64_t samples = 0;       // taken
  std::uint64_t malformed = 0;     // did not parse: garbage, NaN, not a rotation
  std::uint64_t without_body = 0;  // parsed, but the configured body was not in it
  std::uint64_t backwards = 0;     // out of the tracker's sequence: older than the last sample taken, or far ahead
  std::uint64_t flood = 0;         // dropped unread: too soon after the sender's last, or over the read budget
  std::uint64_t other_sender = 0;  // dropped unread, not from viewer.tracking.from
  std::uint64_t losses = 0;        // times the tracker was lost
  clock::Nanos lost_ns = 0;        // time spent lost, up to the last frame

  TrackingCounts& operator+=(const TrackingCounts& more) {
    datagrams += more.datagrams;
    samples += more.samples;
    malformed += more.malformed;
    without_body += more.without_body;
    backwards += more.backwards;
    flood += more.flood;
    other_sender += more.other_sender;
    losses += more.losses;
    lost_ns += more.lost_ns;
    return *this;
  }
  friend bool operator==(const TrackingCounts&, const TrackingCounts&) = default;
};

// The first of a kind of refusal is said (into `said`), the rest only counted:
// a flood of bad input writes one line, not thousands.
inline void say_once(bool& said_before, const std::string& text, std::vector<std::string>& said) {
  if (said_before) return;
  said_before = true;
  said.push_back(text + " (further ones are only counted)");
}

}  // namespace optique::tracking
