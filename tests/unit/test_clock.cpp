// Clocks (common/clock/clock.h) and NTP-style offset estimation
// (common/clock/offset_estimator.h).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <random>

#include "clock/clock.h"
#include "clock/offset_estimator.h"

namespace optique::clock {
namespace {

constexpr Nanos kMs = kNanosPerMilli;
constexpr Nanos kUs = kNanosPerMicro;

// One ping exchange against a known truth: the node's clock reads master − skew
// (so the true offset, master = node + offset, is +skew). The ping leaves the
// node at master time `start`, takes `out` to reach the master, which holds it
// for `hold`, and the pong takes `back` to return.
PingSample exchange(Nanos skew, Nanos start, Nanos out, Nanos hold, Nanos back) {
  PingSample s;
  s.t1 = start - skew;
  s.t2 = start + out;
  s.t3 = s.t2 + hold;
  s.t4 = s.t3 + back - skew;
  return s;
}

// --- estimate_from --------------------------------------------------------------

TEST(EstimateFrom, SymmetricDelaysGiveExactOffset) {
  const PingSample s = exchange(50 * kMs, 1'000 * kMs, 100 * kUs, 0, 100 * kUs);
  const OffsetEstimate e = estimate_from(s);
  EXPECT_EQ(e.offset, 50 * kMs);
  EXPECT_EQ(e.round_trip, 200 * kUs);
}

TEST(EstimateFrom, MasterHoldTimeIsNotPartOfTheRoundTrip) {
  const PingSample s = exchange(50 * kMs, 1'000 * kMs, 100 * kUs, 3 * kMs, 100 * kUs);
  const OffsetEstimate e = estimate_from(s);
  EXPECT_EQ(e.offset, 50 * kMs);
  EXPECT_EQ(e.round_trip, 200 * kUs);
}

TEST(EstimateFrom, NegativeOffsetWhenNodeIsAhead) {
  const PingSample s = exchange(-7 * kMs, 5 * kMs, 40 * kUs, 10 * kUs, 40 * kUs);
  const OffsetEstimate e = estimate_from(s);
  EXPECT_EQ(e.offset, -7 * kMs);
  EXPECT_EQ(e.round_trip, 80 * kUs);
}

TEST(EstimateFrom, AsymmetricDelaysBiasByHalfTheAsymmetry) {
  // 300 µs out, 100 µs back: the estimate is late by (300 − 100) / 2 = 100 µs.
  const PingSample slow_out = exchange(50 * kMs, 1'000 * kMs, 300 * kUs, 20 * kUs, 100 * kUs);
  const OffsetEstimate e1 = estimate_from(slow_out);
  EXPECT_EQ(e1.offset, 50 * kMs + 100 * kUs);
  EXPECT_EQ(e1.round_trip, 400 * kUs);

  // The other way round: early by the same amount.
  const PingSample slow_back = exchange(50 * kMs, 1'000 * kMs, 100 * kUs, 20 * kUs, 300 * kUs);
  const OffsetEstimate e2 = estimate_from(slow_back);
  EXPECT_EQ(e2.offset, 50 * kMs - 100 * kUs);
  EXPECT_EQ(e2.round_trip, 400 * kUs);
}

TEST(EstimateFrom, ClocksFarApartDoNotOverflow) {
  // The node's clock reads about 146 years ahead of the master's: the textbook
  // ((t2 − t1) + (t3 − t4)) would need -2·skew, beyond int64.
  constexpr Nanos skew = INT64_MAX / 2 + 1234;
  const PingSample s = exchange(-skew, 10 * kMs, 100 * kUs, 0, 100 * kUs);
  const OffsetEstimate e = estimate_from(s);
  // Halving each (odd) difference separately truncates: within 1 ns, not exact.
  EXPECT_LE(std::llabs(e.offset - (-skew)), 1) << e.offset;
  EXPECT_EQ(e.round_trip, 200 * kUs);
}

// --- OffsetEstimator --------------------------------------------------------------

TEST(OffsetEstimator, EmptyHasNoEstimate) {
  OffsetEstimator estimator;
  EXPECT_FALSE(estimator.best().has_value());
  EXPECT_EQ(estimator.size(), 0u);
}

TEST(OffsetEstimator, PicksTheLowestRoundTrip) {
  OffsetEstimator estimator(16);
  // Noisy samples; the quiet one (60 µs round trip, 10 µs asymmetry) should win.
  ASSERT_TRUE(estimator.add(exchange(50 * kMs, 0, 900 * kUs, 5 * kUs, 100 * kUs)));
  ASSERT_TRUE(estimator.add(exchange(50 * kMs, 10 * kMs, 35 * kUs, 5 * kUs, 25 * kUs)));
  ASSERT_TRUE(estimator.add(exchange(50 * kMs, 20 * kMs, 100 * kUs, 5 * kUs, 700 * kUs)));
  ASSERT_TRUE(estimator.add(exchange(50 * kMs, 30 * kMs, 200 * kUs, 5 * kUs, 200 * kUs)));
  EXPECT_EQ(estimator.size(), 4u);
  const auto best = estimator.best();
  ASSERT_TRUE(best.has_value());
  EXPECT_EQ(best->round_trip, 60 * kUs);
  EXPECT_EQ(best->offset, 50 * kMs + 5 * kUs);
}

TEST(OffsetEstimator, HonoursItsWindow) {
  OffsetEstimator estimator(3);
  // The best sample comes first and must fall out of the window.
  ASSERT_TRUE(estimator.add(exchange(10 * kMs, 0, 10 * kUs, 0, 10 * kUs)));        // rtt 20
  ASSERT_TRUE(estimator.add(exchange(20 * kMs, 1 * kMs, 50 * kUs, 0, 50 * kUs)));  // rtt 100
  ASSERT_TRUE(estimator.add(exchange(30 * kMs, 2 * kMs, 40 * kUs, 0, 40 * kUs)));  // rtt 80
  ASSERT_EQ(estimator.size(), 3u);
  EXPECT_EQ(estimator.best()->round_trip, 20 * kUs);
  EXPECT_EQ(estimator.best()->offset, 10 * kMs);

  ASSERT_TRUE(estimator.add(exchange(40 * kMs, 3 * kMs, 60 * kUs, 0, 60 * kUs)));  // rtt 120
  EXPECT_EQ(estimator.size(), 3u);
  EXPECT_EQ(estimator.best()->round_trip, 80 * kUs);
  EXPECT_EQ(estimator.best()->offset, 30 * kMs);

  ASSERT_TRUE(estimator.add(exchange(50 * kMs, 4 * kMs, 70 * kUs, 0, 70 * kUs)));  // rtt 140
  ASSERT_TRUE(estimator.add(exchange(60 * kMs, 5 * kMs, 90 * kUs, 0, 90 * kUs)));  // rtt 180
  EXPECT_EQ(estimator.size(), 3u);
  EXPECT_EQ(estimator.best()->round_trip, 120 * kUs);
  EXPECT_EQ(estimator.best()->offset, 40 * kMs);
}

TEST(OffsetEstimator, RejectsPongBeforePing) {
  OffsetEstimator estimator;
  PingSample s = exchange(0, 100 * kMs, 10 * kUs, 0, 10 * kUs);
  s.t4 = s.t1 - 1;
  EXPECT_FALSE(estimator.add(s));
  EXPECT_EQ(estimator.size(), 0u);
  EXPECT_FALSE(estimator.best().has_value());
}

TEST(OffsetEstimator, RejectsMasterSendBeforeReceive) {
  OffsetEstimator estimator;
  PingSample s = exchange(0, 100 * kMs, 10 * kUs, 0, 10 * kUs);
  s.t3 = s.t2 - 1;
  EXPECT_FALSE(estimator.add(s));
  EXPECT_EQ(estimator.size(), 0u);
}

TEST(OffsetEstimator, RejectsHoldLongerThanRoundTrip) {
  OffsetEstimator estimator;
  PingSample s;
  s.t1 = 1'000;
  s.t4 = 2'000;  // 1 µs on the node
  s.t2 = 50'000;
  s.t3 = 52'000;  // 2 µs held on the master: negative round trip
  EXPECT_FALSE(estimator.add(s));
  EXPECT_EQ(estimator.size(), 0u);
}

TEST(OffsetEstimator, RejectedSampleDoesNotDisturbKeptOnes) {
  OffsetEstimator estimator(2);
  ASSERT_TRUE(estimator.add(exchange(5 * kMs, 0, 10 * kUs, 0, 10 * kUs)));
  ASSERT_TRUE(estimator.add(exchange(6 * kMs, 1 * kMs, 30 * kUs, 0, 30 * kUs)));
  PingSample bad = exchange(0, 2 * kMs, 1, 0, 1);
  bad.t4 = bad.t1 - 5;
  EXPECT_FALSE(estimator.add(bad));
  EXPECT_EQ(estimator.size(), 2u);
  EXPECT_EQ(estimator.best()->offset, 5 * kMs);
}

TEST(OffsetEstimator, ZeroRoundTripIsPossible) {
  OffsetEstimator estimator;
  EXPECT_TRUE(estimator.add(exchange(3 * kMs, 0, 0, 0, 0)));
  EXPECT_EQ(estimator.best()->round_trip, 0);
  EXPECT_EQ(estimator.best()->offset, 3 * kMs);
}

// --- drift ---------------------------------------------------------------------------

// A node clock that is `skew` behind the master at master time 0 and runs
// `drift` (a fraction: 200e-6 is 200 ppm) slow: the true offset, master = node +
// offset, is skew + drift·m at master time m.
struct DriftingNode {
  Nanos skew = 0;
  double drift = 0.0;
  [[nodiscard]] Nanos node_time(Nanos master) const {
    return master - skew - static_cast<Nanos>(std::llround(drift * static_cast<double>(master)));
  }
  [[nodiscard]] Nanos true_offset(Nanos master) const { return master - node_time(master); }
};

// Pings as the node sends them: a burst of 8 five milliseconds apart, then one
// every 100 ms, each way taking 25 µs plus an exponential jitter (mean 30 µs,
// independent per leg: asymmetric), and one in twenty held up 2 ms on one leg
// by a busy scheduler. Returns the estimate and the truth at master time `until`.
struct DriftRun {
  Nanos estimate_error = 0;
  double drift_ppm = 0.0;
  std::size_t points = 0;
};

DriftRun run_drifting(const DriftingNode& node, Nanos until, unsigned seed) {
  std::mt19937 random(seed);
  std::exponential_distribution<double> jitter(1.0 / 30'000.0);
  std::uniform_int_distribution<int> one_in_twenty(0, 19);
  OffsetEstimator estimator;
  Nanos m = 0;
  for (int i = 0; m <= until; ++i) {
    Nanos out = 25 * kUs + static_cast<Nanos>(jitter(random));
    Nanos back = 25 * kUs + static_cast<Nanos>(jitter(random));
    if (one_in_twenty(random) == 0) (i % 2 == 0 ? out : back) += 2 * kMs;
    PingSample s;
    s.t1 = node.node_time(m);
    s.t2 = m + out;
    s.t3 = s.t2 + 5 * kUs;
    s.t4 = node.node_time(s.t3 + back);
    EXPECT_TRUE(estimator.add(s));
    m += i < 8 ? 5 * kMs : 100 * kMs;
  }
  const auto estimate = estimator.at(node.node_time(until));
  EXPECT_TRUE(estimate.has_value());
  if (!estimate) return {};
  return {estimate->offset - node.true_offset(until), estimate->drift_ppm, estimate->points};
}

TEST(OffsetEstimator, FollowsA200PpmDriftWithin25MicrosecondsAfterTwoSeconds) {
  for (const double drift : {200e-6, -200e-6}) {
    for (unsigned seed = 1; seed <= 20; ++seed) {
      const DriftRun run = run_drifting({50 * kMs, drift}, 2 * kNanosPerSecond, seed);
      EXPECT_LE(std::abs(run.estimate_error), 25 * kUs) << "drift " << drift * 1e6 << " ppm, seed " << seed;
      EXPECT_NEAR(run.drift_ppm, drift * 1e6, 30.0) << "seed " << seed;
      EXPECT_GE(run.points, 7u) << "the line goes through most of the 11 buckets (a few far off are left out)";
    }
  }
}

TEST(OffsetEstimator, WithoutTheDriftTheQuietestSampleWouldBeFarOff) {
  // What the fit buys: after 2 s at 200 ppm the quietest sample may be from the
  // burst at the start, 400 µs of drift ago.
  OffsetEstimator estimator;
  const DriftingNode node{50 * kMs, 200e-6};
  PingSample quiet;
  quiet.t1 = node.node_time(0);
  quiet.t2 = 10 * kUs;
  quiet.t3 = quiet.t2;
  quiet.t4 = node.node_time(20 * kUs);
  ASSERT_TRUE(estimator.add(quiet));
  for (Nanos m = 100 * kMs; m <= 2 * kNanosPerSecond; m += 100 * kMs) {
    PingSample s;
    s.t1 = node.node_time(m);
    s.t2 = m + 60 * kUs;
    s.t3 = s.t2;
    s.t4 = node.node_time(s.t3 + 60 * kUs);
    ASSERT_TRUE(estimator.add(s));
  }
  const Nanos truth = node.true_offset(2 * kNanosPerSecond);
  EXPECT_GT(std::abs(estimator.best()->offset - truth), 350 * kUs);
  EXPECT_LE(std::abs(estimator.at(node.node_time(2 * kNanosPerSecond))->offset - truth), 2 * kUs);
}

TEST(OffsetEstimator, ABucketWhosePingsAllMetABusyLegDoesNotTiltTheLine) {
  // Pings forty a second, 25 µs each way, on a node 200 ppm slow, except in the
  // last bucket read: there every ping's way out took 80 µs longer (a busy
  // master), so its quietest sample is 40 µs off. The line is read right there.
  const DriftingNode node{50 * kMs, 200e-6};
  const Nanos until = 3 * kNanosPerSecond;
  const auto run = [&](bool busy_end) {
    OffsetEstimator estimator;
    for (Nanos m = 0; m <= until; m += 25 * kMs) {
      const Nanos out = 25 * kUs + (busy_end && m > until - 200 * kMs ? 80 * kUs : 0);
      PingSample s;
      s.t1 = node.node_time(m);
      s.t2 = m + out;
      s.t3 = s.t2 + 5 * kUs;
      s.t4 = node.node_time(s.t3 + 25 * kUs);
      EXPECT_TRUE(estimator.add(s));
    }
    return *estimator.at(node.node_time(until));
  };
  const ClockEstimate clean = run(false);
  EXPECT_LE(std::abs(clean.offset - node.true_offset(until)), 1 * kUs);
  const ClockEstimate busy = run(true);
  EXPECT_LE(std::abs(busy.offset - node.true_offset(until)), 3 * kUs) << "the busy bucket is left out of the fit";
  EXPECT_EQ(busy.points + 1, clean.points);
  EXPECT_NEAR(busy.drift_ppm, 200.0, 2.0);
}

TEST(OffsetEstimator, NoDriftUntilTheSamplesSpanHalfASecond) {
  OffsetEstimator estimator;
  const DriftingNode node{-3 * kMs, 100e-6};
  for (Nanos m = 0; m <= 300 * kMs; m += 100 * kMs) {
    PingSample s;
    s.t1 = node.node_time(m);
    s.t2 = m + 40 * kUs;
    s.t3 = s.t2;
    s.t4 = node.node_time(s.t3 + 40 * kUs);
    ASSERT_TRUE(estimator.add(s));
  }
  const auto estimate = estimator.at(node.node_time(300 * kMs));
  ASSERT_TRUE(estimate.has_value());
  EXPECT_EQ(estimate->points, 1u);
  EXPECT_EQ(estimate->drift_ppm, 0.0);
  EXPECT_EQ(estimate->offset, estimator.best()->offset);
  EXPECT_EQ(estimate->error_bound, estimate->round_trip / 2);
}

TEST(OffsetEstimator, AnImplausibleDriftIsNotExtrapolated) {
  // Offsets that jump 5 ms in a second (5000 ppm): noise or a stepped clock, not
  // quartz. The estimate stays with the quietest sample.
  OffsetEstimator estimator;
  for (Nanos m = 0; m <= 1 * kNanosPerSecond; m += 100 * kMs) {
    ASSERT_TRUE(estimator.add(exchange(m * 5 / 1000, m, 30 * kUs, 0, 30 * kUs)));
  }
  const auto estimate = estimator.at(1 * kNanosPerSecond);
  ASSERT_TRUE(estimate.has_value());
  EXPECT_EQ(estimate->drift_ppm, 0.0);
  EXPECT_EQ(estimate->offset, estimator.best()->offset);
}

// --- LocalClock ----------------------------------------------------------------------

TEST(LocalClock, WithoutSkewIsTheMonotonicClock) {
  const LocalClock plain;
  const Nanos m = monotonic_now();
  EXPECT_EQ(plain.to_local(m), m);
  EXPECT_EQ(plain.to_monotonic(m), m);
  const Nanos before = monotonic_now();
  const Nanos now = plain.now();
  const Nanos after = monotonic_now();
  EXPECT_LE(before, now);
  EXPECT_LE(now, after);
}

TEST(LocalClock, ConstantOffset) {
  const LocalClock clock(-50 * kMs, 0.0);
  const Nanos m = monotonic_now() + 123'456'789;
  EXPECT_EQ(clock.to_local(m), m - 50 * kMs);
  EXPECT_EQ(clock.to_monotonic(m - 50 * kMs), m);
}

TEST(LocalClock, ToLocalAndToMonotonicAreInverseWithin1ns) {
  const Nanos base = monotonic_now();
  for (double ppm : {0.0, 200.0, -200.0, 37.5}) {
    for (Nanos offset : {Nanos{0}, 50 * kMs, -50 * kMs, Nanos{7'777'777'777'777}}) {
      const LocalClock clock(offset, ppm);
      for (Nanos delta = -1'000'000'000'000; delta <= 1'000'000'000'000; delta += 9'999'999'999 + 1) {
        for (Nanos jitter : {Nanos{0}, Nanos{1}, Nanos{333}, Nanos{-77'777}}) {
          const Nanos m = base + delta + jitter;
          const Nanos back = clock.to_monotonic(clock.to_local(m));
          ASSERT_LE(std::llabs(back - m), 1) << "ppm " << ppm << " offset " << offset << " m " << m;
          const Nanos local = m;  // also any local time maps back
          const Nanos there = clock.to_local(clock.to_monotonic(local));
          ASSERT_LE(std::llabs(there - local), 1) << "ppm " << ppm << " offset " << offset << " local " << local;
        }
      }
    }
  }
}

TEST(LocalClock, DriftShowsUpAfterOneSecond) {
  const Nanos base = monotonic_now();
  for (double ppm : {200.0, -200.0}) {
    const LocalClock clock(12 * kMs, ppm);
    const Nanos start = clock.to_local(base);
    const Nanos one_second_later = clock.to_local(base + kNanosPerSecond);
    // 200 ppm of 1 s is 200 µs; ±1 ns for rounding at each end.
    const Nanos expected = kNanosPerSecond + static_cast<Nanos>(ppm * 1'000);
    EXPECT_LE(std::llabs((one_second_later - start) - expected), 1) << "ppm " << ppm;
  }
}

TEST(LocalClock, DriftIsMeasuredFromConstruction) {
  const LocalClock clock(0, 200.0);
  // Right now, the drift has had no time to act: local ≈ monotonic.
  const Nanos m = monotonic_now();
  EXPECT_LE(std::llabs(clock.to_local(m) - m), 1 * kMs);  // ≤ 200 ppm of the ≤ 5 s since construction
}

// --- sleep_until_monotonic -------------------------------------------------------

TEST(SleepUntilMonotonic, NeverReturnsBeforeTheDeadline) {
  for (Nanos ahead : {Nanos{0}, 50 * kUs, 200 * kUs, 1 * kMs, 3 * kMs}) {
    for (Nanos spin : {Nanos{0}, 200 * kUs, 2 * kMs}) {
      for (int i = 0; i < 3; ++i) {
        const Nanos deadline = monotonic_now() + ahead;
        sleep_until_monotonic(deadline, spin);
        const Nanos woke = monotonic_now();
        ASSERT_GE(woke, deadline) << "ahead " << ahead << " spin " << spin;
      }
    }
  }
}

TEST(SleepUntilMonotonic, PastDeadlineReturnsPromptly) {
  const Nanos start = monotonic_now();
  sleep_until_monotonic(start - 10 * kNanosPerSecond);
  EXPECT_LT(monotonic_now() - start, 100 * kMs);
}

TEST(SleepUntilMonotonic, DoesNotOversleepGrossly) {
  const Nanos deadline = monotonic_now() + 5 * kMs;
  sleep_until_monotonic(deadline);
  // Generous: a loaded CI machine may wake late, but not by a second.
  EXPECT_LT(monotonic_now() - deadline, 1 * kNanosPerSecond);
}

}  // namespace
}  // namespace optique::clock
