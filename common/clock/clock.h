#pragma once
// Time in optique is int64 nanoseconds. Protocol times are on the master's clock;
// each process reads its own monotonic clock, which a node maps to the master's
// with an estimated offset (clock/offset_estimator.h).

#include <chrono>
#include <cstdint>
#include <type_traits>

namespace optique::clock {

using Nanos = std::int64_t;

inline constexpr Nanos kNanosPerMicro = 1'000;
inline constexpr Nanos kNanosPerMilli = 1'000'000;
inline constexpr Nanos kNanosPerSecond = 1'000'000'000;

// A std::chrono duration (a config's timeout) in Nanos: whole units only, so
// that nothing is cut off unseen.
template <class Rep, class Period>
[[nodiscard]] constexpr Nanos nanos(std::chrono::duration<Rep, Period> d) {
  static_assert(std::is_integral_v<Rep>, "clock::nanos takes a duration in whole units");
  return std::chrono::duration_cast<std::chrono::nanoseconds>(d).count();
}

// The simulation's frame period at `frame_rate` Hz, in whole nanoseconds:
// frame k happens at simulation time k·period (the master's scene and the
// live scene's animation clocks both count so).
[[nodiscard]] constexpr Nanos frame_period(double frame_rate) { return static_cast<Nanos>(1e9 / frame_rate); }

// CLOCK_MONOTONIC in nanoseconds.
[[nodiscard]] Nanos monotonic_now();

// A process's own clock: the monotonic clock, optionally skewed by a fixed offset
// and a drift (test hooks, so tests can check clock estimation against a known
// truth on one machine). local(t) = t + offset + drift_ppm·1e-6·(t − epoch).
class LocalClock {
 public:
  LocalClock() : LocalClock(0, 0.0) {}
  LocalClock(Nanos offset, double drift_ppm);

  [[nodiscard]] Nanos now() const { return to_local(monotonic_now()); }
  [[nodiscard]] Nanos to_local(Nanos monotonic) const;
  [[nodiscard]] Nanos to_monotonic(Nanos local) const;
  // Skewed on purpose: on one machine, the true offset to a master that reads
  // the monotonic clock is then known (monotonic − local).
  [[nodiscard]] bool skewed() const { return offset_ != 0 || drift_ != 0.0; }

 private:
  Nanos offset_;
  double drift_;
  Nanos epoch_;
};

// Sleeps until the monotonic time `deadline`: a coarse sleep, then a short spin
// for the last `spin` nanoseconds, because a sleep alone wakes up late by the
// scheduler's slack.
void sleep_until_monotonic(Nanos deadline, Nanos spin = 200 * kNanosPerMicro);

}  // namespace optique::clock
