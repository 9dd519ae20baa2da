#pragma once
// Which of the tracker's frames belong to its sequence, without IO. The
// established sequence (its frame counter, else its timestamp) is followed while
// it goes on: a frame after the newest taken, and not further ahead than the time
// since could bring. Any other frame (older, or far ahead) is believed only as a
// tracker that restarted: a new sequence from one sender that goes on for
// kRestartDatagrams datagrams over kRestartSpan with no frame of the established
// sequence taken in between. So one forged datagram with a counter far ahead, or
// a few between the real ones, never takes the head from the tracker, and a
// tracker that really restarted is followed within a few frames. Quiet for
// `quiet` (lost), the sequence is over: whatever comes next starts a new one.

#include <cstdint>
#include <optional>
#include <string>

#include "clock/clock.h"
#include "tracking/dtrack_reader.h"

namespace optique::tracking {

// A new sequence is believed after this many datagrams spanning this long (a
// 60 Hz tracker restarted: its fourth frame, 50 ms on).
inline constexpr int kRestartDatagrams = 4;
inline constexpr Nanos kRestartSpan = 40'000'000;
// How far ahead of the newest taken a frame may be and still go on from it:
// this many frames, and kMostFrameRate a second since (DTrack sends at most 300);
// a timestamp this many seconds, and two seconds a second since.
inline constexpr std::uint64_t kFramesAhead = 10;
inline constexpr double kMostFrameRate = 1000.0;
inline constexpr double kTimestampAhead = 0.05;

enum class Order {
  next,     // goes on from the established sequence (or starts the first one)
  restart,  // a new sequence, now believed: what was known of the head is stale
  outside,  // neither: ignored
};

class FrameSequence {
 public:
  explicit FrameSequence(Nanos quiet) : quiet_(quiet) {}

  // Where `sample` stands; an outside one may be the start of a new sequence,
  // remembered.
  [[nodiscard]] Order order(const DTrackSample& sample);
  // `sample` was taken: the newest of the established sequence.
  void taken(const DTrackSample& sample);

 private:
  struct Newest {
    Nanos arrival = 0;
    std::optional<std::uint64_t> frame;
    std::optional<double> timestamp;
  };
  struct Candidate {
    std::string sender;
    Nanos since = 0;
    Newest newest;
    int datagrams = 0;
  };
  [[nodiscard]] static bool goes_on(const Newest& from, const DTrackSample& sample);

  Nanos quiet_;
  std::optional<Newest> established_;
  std::optional<Candidate> candidate_;
};

}  // namespace optique::tracking
