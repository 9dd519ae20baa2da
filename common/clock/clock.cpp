#include "clock/clock.h"

#include <cmath>
#include <ctime>
#include <thread>

namespace optique::clock {

Nanos monotonic_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<Nanos>(ts.tv_sec) * kNanosPerSecond + ts.tv_nsec;
}

LocalClock::LocalClock(Nanos offset, double drift_ppm)
    : offset_(offset), drift_(drift_ppm * 1e-6), epoch_(monotonic_now()) {}

Nanos LocalClock::to_local(Nanos monotonic) const {
  const auto drifted = static_cast<Nanos>(std::llround(drift_ * static_cast<double>(monotonic - epoch_)));
  return monotonic + offset_ + drifted;
}

Nanos LocalClock::to_monotonic(Nanos local) const {
  const double since_epoch = static_cast<double>(local - offset_ - epoch_) / (1.0 + drift_);
  return epoch_ + static_cast<Nanos>(std::llround(since_epoch));
}

void sleep_until_monotonic(Nanos deadline, Nanos spin) {
  const Nanos coarse = deadline - spin;
  Nanos now = monotonic_now();
  if (coarse > now) {
    timespec ts{};
    ts.tv_sec = coarse / kNanosPerSecond;
    ts.tv_nsec = coarse % kNanosPerSecond;
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
    }
  }
  while (monotonic_now() < deadline) {
    std::this_thread::yield();
  }
}

}  // namespace optique::clock
