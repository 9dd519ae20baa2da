// A tracked head without IO (common/tracking): DTrack's ASCII output and replay
// files parsed, samples stamped and carried to the world, the head predicted,
// bad input ignored and counted, a lost tracker held and eased to rest.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include "config/address.h"
#include "config/tracking.h"
#include "tracking/dtrack.h"
#include "tracking/dtrack_reader.h"
#include "tracking/head_tracker.h"
#include "tracking/predictor.h"
#include "tracking/replay.h"

namespace optique::tracking {
namespace {

constexpr Nanos kMs = 1'000'000;

// The head at display time `time`, noticed at `now`.
HeadAt at(HeadTracker& tracker, Nanos time, Nanos now, const glm::dvec3& rest, std::vector<std::string>& said) {
  tracker.notice(now, said);
  return tracker.at(time, rest);
}

// A DTrack frame with body `id` at `mm` (tracker space), turned `degrees` about
// the tracker's z axis.
std::string datagram(std::uint64_t frame, std::uint32_t id, glm::dvec3 mm, double degrees = 0.0) {
  const double a = glm::radians(degrees);
  const double c = std::cos(a);
  const double s = std::sin(a);
  char text[512];
  // Column by column: the body's x axis (c, s, 0), y (−s, c, 0), z (0, 0, 1).
  std::snprintf(text, sizeof text,
                "fr %llu\r\nts %.6f\r\n6dcal 2\r\n6d 1 [%u 1.000][%.3f %.3f %.3f][%.6f %.6f %.6f %.6f %.6f %.6f 0 0 "
                "1]\r\n6df 0\r\n",
                static_cast<unsigned long long>(frame), 0.01 * static_cast<double>(frame), id, mm.x, mm.y, mm.z, c, s,
                0.0, -s, c, 0.0);
  return text;
}

TEST(DTrack, ParsesFramesTimestampsAndBodies) {
  const auto parsed = parse_dtrack(
      "fr 21753\r\nts 39596.024831\r\n6dcal 2\r\n"
      "6d 2 [0 1.000][326.848 -187.216 109.503][1 0 0 0 1 0 0 0 1] "
      "[3 0.500][-1 2 3 -160.4704 -3.6963 -7.0913][0 1 0 -1 0 0 0 0 1]\r\n"
      "3d 1 [7 1.000][1 2 3]\r\n");
  ASSERT_TRUE(parsed) << parsed.error();
  const DTrackFrame& f = parsed.value();
  EXPECT_EQ(f.frame, 21753u);
  ASSERT_TRUE(f.timestamp);
  EXPECT_DOUBLE_EQ(*f.timestamp, 39596.024831);
  ASSERT_EQ(f.bodies.size(), 2u);
  EXPECT_EQ(f.bodies[0].id, 0u);
  EXPECT_DOUBLE_EQ(f.bodies[0].position.y, -187.216);
  EXPECT_EQ(f.bodies[1].id, 3u);
  EXPECT_DOUBLE_EQ(f.bodies[1].quality, 0.5);
  // Column by column: the body's x axis is the tracker's y.
  EXPECT_DOUBLE_EQ(f.bodies[1].rotation[0][1], 1.0);
  EXPECT_DOUBLE_EQ(f.bodies[1].rotation[1][0], -1.0);
}

TEST(DTrack, TheExtendedTimestampCarriesTheTrackersLatency) {
  const auto parsed = parse_dtrack("ts2 1700000000 250000 18000\n6d 0\n");
  ASSERT_TRUE(parsed) << parsed.error();
  ASSERT_TRUE(parsed.value().latency);
  EXPECT_DOUBLE_EQ(*parsed.value().latency, 0.018);
  EXPECT_TRUE(parsed.value().bodies.empty());
}

TEST(DTrack, MalformedDatagramsAreRefusedNamingTheLine) {
  const struct {
    const char* text;
    const char* says;
  } cases[] = {
      {"fr 1\n6d 1 [0 1][nan 0 0][1 0 0 0 1 0 0 0 1]\n", "line 2 (6d): body 1 of 1: expected [x y z]"},
      {"6d 1 [0 1][0 0 0][1 0 0 0 1 0 0 0 2]\n", "the rotation matrix is not a rotation"},
      {"6d 1 [0 1][0 0 0][-1 0 0 0 1 0 0 0 1]\n", "the rotation matrix is not a rotation"},  // a mirror
      {"6d 2 [0 1][0 0 0][1 0 0 0 1 0 0 0 1]\n", "body 2 of 2: expected [id quality]"},
      {"6d 1 [0 1][0 0 0][1 0 0 0 1 0 0 0 1] junk\n", "more after the 1 bodies"},
      {"6d 99999 \n", "99999 bodies"},
      {"fr x\n", "line 1 (fr): expected a frame counter"},
      {"ts -3\n", "expected seconds since midnight"},
      {"ts2 1 2000000 0\n", "expected seconds, microseconds"},
      {"fr 1\x01\n", "a byte that is not printable ASCII"},
      {"\x7f\x45\x4c\x46\n", "a byte that is not printable ASCII"},
      {"hello\nworld\n", "no fr, ts or 6d line"},
      {"6d 1 [0 7][0 0 0][1 0 0 0 1 0 0 0 1]\n", "quality 7"},
  };
  for (const auto& c : cases) {
    const auto parsed = parse_dtrack(c.text);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_NE(parsed.error().find(c.says), std::string::npos) << parsed.error();
  }
  EXPECT_FALSE(parse_dtrack(std::string(kMaxDTrackDatagram + 1, ' ')));
}

// A flystick (6df2): its pose as a body's, its buttons as bits of 32-bit
// words, its joystick's axes; one the cameras do not see (quality -1, a pose
// of zeros) still gives its buttons.
TEST(DTrack, FlysticksGiveTheirButtonsAndJoystick) {
  const auto parsed = parse_dtrack(
      "fr 7\n6df2 2 2 [0 1.000 6 2][100 200 300][1 0 0 0 1 0 0 0 1][5 0.5 -1.0] "
      "[1 -1.000 40 1][0 0 0][0 0 0 0 0 0 0 0 0][2147483649 2 0.25]\n");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  ASSERT_EQ(parsed.value().flysticks.size(), 2u);
  const DTrackFlystick& first = parsed.value().flysticks[0];
  EXPECT_EQ(first.body.id, 0u);
  EXPECT_EQ(first.body.position, glm::dvec3(100.0, 200.0, 300.0));
  EXPECT_EQ(first.buttons, (std::vector<bool>{true, false, true, false, false, false}));
  EXPECT_EQ(first.controllers, (std::vector<double>{0.5, -1.0}));
  const DTrackFlystick& unseen = parsed.value().flysticks[1];
  EXPECT_EQ(unseen.body.quality, -1.0);
  EXPECT_EQ(unseen.body.rotation, glm::dmat3(1.0));
  ASSERT_EQ(unseen.buttons.size(), 40u);
  for (std::size_t b = 0; b < 40; ++b) {
    EXPECT_EQ(unseen.buttons[b], b == 0 || b == 31 || b == 33) << "button " << b;  // 2^31 + 1, then 2 = bit 1 of word 2
  }
  EXPECT_EQ(unseen.controllers, std::vector<double>{0.25});
  EXPECT_TRUE(parsed.value().bodies.empty());
}

TEST(DTrack, MalformedFlysticksAreRefusedNamingWhat) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"6df2 1 1 [0 1 6 2][0 0 0][1 0 0 0 1 0 0 0 1][5 0.5]\n",
       "flystick 1 of 1: expected 2 controller values in -1…1"},
      {"6df2 1 1 [0 1 6 2][0 0 0][1 0 0 0 1 0 0 0 1][5 0.5 1.5]\n", "expected 2 controller values in -1…1"},
      {"6df2 1 1 [0 1 6 2][0 0 0][1 0 0 0 1 0 0 0 1][x 0 0]\n", "expected the buttons as 1 whole number(s)"},
      {"6df2 1 1 [0 1 6 2][0 0 0][1 0 0 0 1 0 0 0 1]\n", "expected [buttons controllers] after the rotation matrix"},
      {"6df2 1 1 [0 1 6000 2][0 0 0][1 0 0 0 1 0 0 0 1][0 0 0]\n",
       "6000 buttons and 2 controllers (at most 64 and 16)"},
      {"6df2 1 1 [0 1 6 2][0 0 0][0 0 0 0 0 0 0 0 0][0 0 0]\n", "the rotation matrix is not a rotation"},
      {"6df2 1 1 [0 1 0 0][0 0 0][1 0 0 0 1 0 0 0 1][] junk\n", "more after the 1 flysticks"},
      {"6df2 1 1 [0 1 0 0][0 0 0][1 0 0 0 1 0 0 0 1][]\n6df2 1 0\n", "a second 6df2 line"},
  };
  for (const auto& [datagram, error] : cases) {
    const auto parsed = parse_dtrack("fr 1\n" + datagram);
    ASSERT_FALSE(parsed.ok()) << datagram;
    EXPECT_NE(parsed.error().find(error), std::string::npos) << parsed.error();
  }
  EXPECT_TRUE(parse_dtrack("fr 1\n6df2 1 1 [0 1 0 0][0 0 0][1 0 0 0 1 0 0 0 1][]\n").ok()) << "no buttons at all";
}

TEST(DTrack, DTrackOnesPositionBlockWithAnglesIsRead) {
  const auto parsed = parse_dtrack("6d 1 [2 1.0][10 20 30 1 2 3][1 0 0 0 1 0 0 0 1]");
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_DOUBLE_EQ(parsed.value().bodies.at(0).position.z, 30.0);
}

config::Tracking settings(config::HeadPrediction prediction = config::HeadPrediction::none) {
  config::Tracking t;
  t.body = 4;
  t.prediction = prediction;
  return t;
}

// A tracker whose z is the world's up (y): its x is the world's x, its y the
// world's −z. The eyes sit 10 cm in front of the tracked body (its own −z).
TEST(HeadTracker, SamplesAreCarriedToTheWorldAndToTheEyes) {
  config::Tracking t = settings();
  t.tracker_axes = glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  t.tracker_origin = {0.0, 0.0, 1.0};
  t.eye_offset = {0.0, 0.0, -0.1};
  HeadTracker tracker(t);
  EXPECT_FALSE(tracker.datagram(datagram(1, 4, {100.0, 200.0, 1700.0}), 10 * kMs));
  std::vector<std::string> said;
  const HeadAt head = at(tracker, 10 * kMs, 10 * kMs, {0.0, 1.2, 2.0}, said);
  EXPECT_EQ(head.state, TrackerState::tracking);
  // Body at (0.1, 1.7, 1 − 0.2); the body unturned, its −z is the world's −y.
  EXPECT_NEAR(head.pose.position.x, 0.1, 1e-12);
  EXPECT_NEAR(head.pose.position.y, 1.7 - 0.1, 1e-12);
  EXPECT_NEAR(head.pose.position.z, 0.8, 1e-12);
  // Turned 90° about the tracker's z (the world's up): the head's right (x) is
  // the tracker's y, the world's −z.
  EXPECT_FALSE(tracker.datagram(datagram(2, 4, {0.0, 0.0, 1700.0}, 90.0), 20 * kMs));
  const HeadAt turned = at(tracker, 20 * kMs, 20 * kMs, {0.0, 1.2, 2.0}, said);
  const glm::dvec3 right = turned.pose.orientation * glm::dvec3(1.0, 0.0, 0.0);
  EXPECT_NEAR(right.x, 0.0, 1e-6);
  EXPECT_NEAR(right.z, -1.0, 1e-6);
  EXPECT_TRUE(said.empty());
}

// What a bad tracker sends is ignored and counted, and the frame goes on with
// the good samples.
TEST(HeadTracker, BadInputIsIgnoredAndCounted) {
  HeadTracker tracker(settings());
  Nanos t = 0;
  const auto next = [&] { return t += 10 * kMs; };
  EXPECT_FALSE(tracker.datagram(datagram(10, 4, {0, 1000, 0}), next()));
  const auto garbage = tracker.datagram("GET / HTTP/1.1", next());
  ASSERT_TRUE(garbage);
  EXPECT_NE(garbage->find("not DTrack's ASCII output"), std::string::npos) << *garbage;
  EXPECT_FALSE(tracker.datagram("6d 1 [4 1][nan 0 0][1 0 0 0 1 0 0 0 1]", next())) << "said once only";
  const auto other = tracker.datagram(datagram(11, 5, {0, 1000, 0}), next());
  ASSERT_TRUE(other);
  EXPECT_NE(other->find("without body 4 (bodies 5)"), std::string::npos) << *other;
  const auto old = tracker.datagram(datagram(9, 4, {0, 1000, 0}), next());
  ASSERT_TRUE(old);
  EXPECT_NE(old->find("older than the last one"), std::string::npos);
  // A flood: 100 datagrams 10 µs apart; one is read every kFloodInterval.
  const Nanos flood_start = next();
  for (int i = 0; i < 100; ++i) {
    (void)tracker.datagram(datagram(12 + i / 50, 4, {0, 1000, 0}), flood_start + i * 10'000);
  }
  const TrackingCounts& counts = tracker.counts();
  EXPECT_EQ(counts.samples, 2u);
  EXPECT_EQ(counts.malformed, 2u);
  EXPECT_EQ(counts.without_body, 1u);
  EXPECT_EQ(counts.backwards, 1u);
  EXPECT_EQ(counts.flood, 99u);  // 98 unread, one read but under 1 ms after the last sample
  EXPECT_EQ(counts.datagrams, 105u);
  // A tracker that started again (its counter far back, going on from there) is followed.
  std::optional<std::string> restarted;
  for (int i = 0; i < kRestartDatagrams; ++i) {
    restarted = tracker.datagram(datagram(3 + i, 4, {0, 1500, 0}), flood_start + (20 + 16 * i) * kMs);
  }
  ASSERT_TRUE(restarted);
  EXPECT_NE(restarted->find("started again"), std::string::npos);
  const Nanos now = flood_start + (20 + 16 * (kRestartDatagrams - 1)) * kMs;
  std::vector<std::string> said;
  EXPECT_NEAR(at(tracker, now, now, {}, said).pose.position.y, 1.5, 1e-12);
}

// The flood rule is each sender's: a host that floods the port at 100 kHz does
// not starve the tracker's 60 Hz. With `from`, only the tracker is heard.
TEST(HeadTracker, AFloodingHostDoesNotStarveTheTracker) {
  HeadTracker tracker(settings());
  std::uint64_t frame = 1;
  for (Nanos t = 0; t < 1000 * kMs; t += 10'000) {
    if (t % (16 * kMs) == 0) {
      EXPECT_FALSE(tracker.datagram(datagram(frame++, 4, {0, 1000, 0}), t, "10.0.0.2")) << "the tracker at " << t;
    }
    (void)tracker.datagram("junk", t + 1'000, "10.0.0.66");
  }
  EXPECT_EQ(tracker.counts().samples, frame - 1) << "every sample of the tracker taken";
  EXPECT_GT(tracker.counts().flood, 90'000u) << "the flood dropped unread";
  EXPECT_LT(tracker.counts().malformed, 2'100u) << "at most one junk datagram read every 0.5 ms";

  config::Tracking only = settings();
  only.from = "10.0.0.2";
  HeadTracker filtered(only);
  const auto said = filtered.datagram(datagram(1, 4, {0, 1000, 0}), 10 * kMs, "10.0.0.66");
  ASSERT_TRUE(said);
  EXPECT_NE(said->find("ignored datagrams from 10.0.0.66: viewer.tracking.from is 10.0.0.2"), std::string::npos);
  EXPECT_FALSE(filtered.datagram(datagram(2, 4, {0, 1000, 0}), 20 * kMs, "10.0.0.2"));
  EXPECT_EQ(filtered.counts().other_sender, 1u);
  EXPECT_EQ(filtered.counts().samples, 1u);
  // Many senders: the one heard from longest ago is forgotten; the flood rule
  // still holds for those remembered.
  HeadTracker crowded(settings());
  const auto sender = [](int i) { return "10.1." + std::to_string(i / 256) + "." + std::to_string(i % 256); };
  // (One sender a frame, so that the read budget is never what drops them.)
  const auto heard = [](int i) { return 10 * kMs + i * 17 * kMs; };
  for (int i = 0; i < 1000; ++i) (void)crowded.datagram("junk", heard(i), sender(i));
  EXPECT_EQ(crowded.counts().malformed, 1000u) << "each sender's first datagram is read";
  (void)crowded.datagram("junk", heard(999) + 1000, sender(999));
  EXPECT_EQ(crowded.counts().flood, 1u) << "a remembered sender, again within 0.5 ms";
  (void)crowded.datagram("junk", heard(999) + 1001, sender(0));
  EXPECT_EQ(crowded.counts().malformed, 1001u) << "a forgotten sender is read again";
  // Spelled otherwise, the tracker's address is still the tracker's.
  config::Tracking mapped = settings();
  mapped.from = config::canonical_address("::ffff:10.0.0.2");
  EXPECT_EQ(mapped.from, "10.0.0.2");
  EXPECT_EQ(config::canonical_address("2001:DB8:0:0::1"), "2001:db8::1");
}

// The tracker's own latency (ts2) and the configured one place a sample at the
// moment it shows; a prediction from constant motion is exact.
TEST(HeadTracker, ConstantVelocityPredictsConstantMotionExactly) {
  config::Tracking t = settings(config::HeadPrediction::constant_velocity);
  t.latency = std::chrono::milliseconds(5);
  HeadTracker tracker(t);
  // 1.5 m/s along x; each sample shows the head 15 + 5 ms before it arrives.
  for (int i = 0; i < 10; ++i) {
    const Nanos shows = i * 16 * kMs;
    const double x = 1.5 * static_cast<double>(shows) / 1e9;
    const std::string text = "fr " + std::to_string(i) + "\nts2 0 0 15000\n6d 1 [4 1][" + std::to_string(x * 1000.0) +
                             " 0 0][1 0 0 0 1 0 0 0 1]\n";
    EXPECT_FALSE(tracker.datagram(text, shows + 20 * kMs));
  }
  std::vector<std::string> said;
  const Nanos display = 9 * 16 * kMs + 50 * kMs;
  const HeadAt head = at(tracker, display, 9 * 16 * kMs + 20 * kMs, {}, said);
  EXPECT_NEAR(head.pose.position.x, 1.5 * static_cast<double>(display) / 1e9, 1e-6);
}

// Hostile stamps: two samples 0.5 ms apart by arrival but stamped 1 ns apart
// by their latencies, at the ends of the room; the head stays finite and moves
// no faster than a head can.
TEST(HeadTracker, StampsTooCloseAndFarPositionsCannotThrowTheHead) {
  for (auto prediction : {config::HeadPrediction::constant_velocity, config::HeadPrediction::double_exponential}) {
    HeadTracker tracker(settings(prediction));
    EXPECT_FALSE(tracker.datagram("fr 1\nts2 0 0 0\n6d 1 [4 1][-99000 0 0][1 0 0 0 1 0 0 0 1]", 10 * kMs));
    EXPECT_TRUE(tracker.datagram("fr 2\nts2 0 0 499\n6d 1 [4 1][99000 0 0][1 0 0 0 1 0 0 0 1]", 10 * kMs + 500'000));
    EXPECT_FALSE(tracker.datagram("fr 3\nts2 0 0 0\n6d 1 [4 1][99000 0 0][1 0 0 0 1 0 0 0 1]", 30 * kMs));
    std::vector<std::string> said;
    const HeadAt head = at(tracker, 80 * kMs, 30 * kMs, {}, said);
    EXPECT_TRUE(std::isfinite(head.pose.position.x));
    EXPECT_LE(glm::distance(head.pose.position, glm::dvec3(99.0, 0.0, 0.0)), kMostHeadSpeed * 0.05 + 1e-9);
    EXPECT_EQ(tracker.counts().flood, 1u) << "the second is under 1 ms after the first";
  }
  EXPECT_FALSE(parse_dtrack("6d 1 [4 1][1e308 0 0][1 0 0 0 1 0 0 0 1]"));
  EXPECT_FALSE(parse_dtrack("ts2 0 0 5000000\n"));
}

// A tracker that really restarts, its counter low and going on, is followed
// within a few frames (kRestartDatagrams, over kRestartSpan).
TEST(HeadTracker, ATrackerThatStartsAgainIsFollowedWithinAFewFrames) {
  HeadTracker tracker(settings());
  for (int i = 0; i < 60; ++i) EXPECT_FALSE(tracker.datagram(datagram(5000 + i, 4, {0, 1000, 0}), i * 16 * kMs));
  int followed_at = -1;
  for (int i = 0; i < 40 && followed_at < 0; ++i) {
    const auto said = tracker.datagram(datagram(1 + i, 4, {0, 1500, 0}), (60 + i) * 16 * kMs);
    if (said && said->find("started again") != std::string::npos) followed_at = i;
  }
  EXPECT_EQ(followed_at, 3) << "the first three are out of sequence; the fourth, 50 ms on, is believed";
  std::vector<std::string> said;
  EXPECT_NEAR(at(tracker, 64 * 16 * kMs, 64 * 16 * kMs, {}, said).pose.position.y, 1.5, 1e-12);
  EXPECT_EQ(tracker.counts().backwards, 3u);
}

// One forged datagram every 30 frames (0.5 s at 60 Hz), its counter 900 ahead of
// the tracker's and going on as the tracker's does, the head 9 m away: the head
// stays with the tracker, every frame, and is never lost; so from the tracker's
// own address, and a forger that sends a few in a row between two of the
// tracker's frames does not get through either.
TEST(HeadTracker, ForgedFramesFarAheadNeverTakeTheHead) {
  for (const char* forger : {"10.0.0.66", "10.0.0.2"}) {
    for (int burst : {1, 8}) {
      config::Tracking t = settings();
      t.lost_after = std::chrono::milliseconds(100);
      HeadTracker tracker(t);
      std::vector<std::string> said;
      double worst = 0.0;
      std::uint64_t forged = 0;
      for (int i = 0; i < 600; ++i) {
        const Nanos now = static_cast<Nanos>(i) * 16'666'667;
        const glm::dvec3 real{1000.0 * 0.001 * i, 1600.0, 0.0};  // 1 mm a frame
        (void)tracker.datagram(datagram(7000 + i, 4, real), now, "10.0.0.2");
        if (i % 30 == 15) {
          for (int k = 0; k < burst; ++k, ++forged) {
            (void)tracker.datagram(datagram(7900 + i + k, 4, real + glm::dvec3(9000, 0, 3000)), now + (2 + k) * kMs,
                                   forger);
          }
        }
        const HeadAt head = at(tracker, now + 8 * kMs, now + 8 * kMs, {}, said);
        EXPECT_EQ(head.state, TrackerState::tracking) << forger << " frame " << i;
        worst = std::max(worst, glm::distance(head.pose.position, real * 0.001));
      }
      EXPECT_LT(worst, 1e-9) << forger << ", bursts of " << burst << ": the head went where the forger put it";
      EXPECT_EQ(tracker.counts().samples, 600u) << forger;
      EXPECT_EQ(tracker.counts().backwards, forged) << forger;
      EXPECT_EQ(tracker.counts().losses, 0u) << forger;
    }
  }
}

// Lost, the eyes stay where they were shown as the tracker went quiet (the
// prediction then), not where the last sample was: no snap back.
TEST(HeadTracker, ALostHeadIsHeldWhereItWasShown) {
  config::Tracking t = settings(config::HeadPrediction::constant_velocity);
  t.lost_after = std::chrono::milliseconds(100);
  HeadTracker tracker(t);
  for (int i = 0; i < 4; ++i)
    EXPECT_FALSE(tracker.datagram(datagram(1 + i, 4, {1000.0 * 0.01 * i, 0, 0}), i * 10 * kMs));
  std::vector<std::string> said;
  const double shown = at(tracker, 130 * kMs, 130 * kMs, {}, said).pose.position.x;  // 1 m/s, 100 ms on
  EXPECT_NEAR(shown, 0.13, 1e-9);
  const HeadAt held = at(tracker, 140 * kMs, 140 * kMs, {}, said);  // lost at 130
  EXPECT_EQ(held.state, TrackerState::holding);
  EXPECT_NEAR(held.pose.position.x, 0.13, 1e-9);
}

// At rest, the eyes lie along the world's x, whatever axis of the body is its right.
TEST(HeadTracker, AtRestTheEyesLieAlongTheWorldsX) {
  for (const glm::dvec3 right :
       {glm::dvec3(0, 1, 0), glm::dvec3(0, 0, -1), glm::dvec3(-1, 0, 0), glm::dvec3(1, 0, 0)}) {
    HeadTracker tracker(settings(), turn_onto_x(right));
    const glm::dvec3 seen = tracker.at(0, {}).pose.orientation * right;
    EXPECT_LT(glm::distance(seen, glm::dvec3(1.0, 0.0, 0.0)), 1e-12) << right.x << " " << right.y << " " << right.z;
  }
}

TEST(HeadPredictor, DoubleExponentialFollowsSteadyMotionWithoutLag) {
  HeadPredictor predictor(config::HeadPrediction::double_exponential, 0.5);
  const glm::dvec3 velocity{0.5, 0.0, -1.0};  // m/s
  const double spin = 1.0;                    // rad/s about y
  Nanos t = 0;
  for (int i = 0; i < 60; ++i) {
    t = i * 10 * kMs;
    const double s = static_cast<double>(t) / 1e9;
    predictor.add(t, {velocity * s, glm::angleAxis(spin * s, glm::dvec3(0, 1, 0))});
  }
  const Nanos ahead = t + 50 * kMs;
  const double s = static_cast<double>(ahead) / 1e9;
  const HeadPose p = predictor.predict(ahead);
  EXPECT_LT(glm::length(p.position - velocity * s), 1e-6);
  EXPECT_LT(glm::angle(p.orientation * glm::inverse(glm::angleAxis(spin * s, glm::dvec3(0, 1, 0)))), 2e-3);
  // Without prediction, 50 ms behind.
  HeadPredictor none(config::HeadPrediction::none, 0.5);
  none.add(t, {velocity * (static_cast<double>(t) / 1e9), {}});
  EXPECT_NEAR(glm::length(none.predict(ahead).position - velocity * s), glm::length(velocity) * 0.05, 1e-9);
}

// Lost: held, eased (smoothstep) to the rest, resting; back on the next sample.
TEST(HeadTracker, ALostTrackerIsHeldThenEasedToRest) {
  config::Tracking t = settings();
  t.lost_after = std::chrono::milliseconds(100);
  t.hold = std::chrono::milliseconds(200);
  t.ease = std::chrono::milliseconds(400);
  HeadTracker tracker(t);
  std::vector<std::string> said;
  const glm::dvec3 rest{0.0, 1.2, 2.0};
  EXPECT_EQ(at(tracker, 0, 0, rest, said).state, TrackerState::waiting);
  EXPECT_EQ(at(tracker, 0, 0, rest, said).pose.position, rest);
  EXPECT_FALSE(tracker.datagram(datagram(1, 4, {1000, 1000, 1000}, 30.0), 0));
  const glm::dvec3 seen{1.0, 1.0, 1.0};
  EXPECT_EQ(at(tracker, 50 * kMs, 50 * kMs, rest, said).state, TrackerState::tracking);
  HeadAt held = at(tracker, 150 * kMs, 150 * kMs, rest, said);
  EXPECT_EQ(held.state, TrackerState::holding);
  EXPECT_EQ(held.pose.position, seen);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("tracker: lost (no sample for 100 ms)"), std::string::npos) << said[0];
  const HeadAt half = at(tracker, 500 * kMs, 500 * kMs, rest, said);  // lost at 100, eased from 300 to 700
  EXPECT_EQ(half.state, TrackerState::easing);
  EXPECT_LT(glm::length(half.pose.position - (seen + rest) * 0.5), 1e-12);
  const HeadAt rested = at(tracker, 800 * kMs, 800 * kMs, rest, said);
  EXPECT_EQ(rested.state, TrackerState::resting);
  EXPECT_EQ(rested.pose.position, rest);
  EXPECT_LT(glm::angle(rested.pose.orientation), 1e-9);
  EXPECT_EQ(said.size(), 1u) << "lost once, said once";
  EXPECT_FALSE(tracker.datagram(datagram(2, 4, {0, 1600, 0}), 900 * kMs));
  const HeadAt back = at(tracker, 900 * kMs, 900 * kMs, rest, said);
  EXPECT_EQ(back.state, TrackerState::tracking);
  EXPECT_NEAR(back.pose.position.y, 1.6, 1e-12);
  ASSERT_EQ(said.size(), 2u);
  EXPECT_NE(said[1].find("tracker: back after 800 ms"), std::string::npos) << said[1];
  EXPECT_EQ(tracker.counts().losses, 1u);
  EXPECT_EQ(tracker.counts().lost_ns, 800 * kMs);
}

// 100 m is a distance from the tracker's origin, not a bound on each axis: a
// body 173 m away is refused, one 98.7 m away taken.
TEST(DTrack, APositionMoreThan100MetresAwayIsRefused) {
  const auto far = parse_dtrack("6d 1 [0 1][100000 100000 100000][1 0 0 0 1 0 0 0 1]");
  ASSERT_FALSE(far);
  EXPECT_NE(far.error().find("more than 100 m from the tracker's origin"), std::string::npos) << far.error();
  EXPECT_TRUE(parse_dtrack("6d 1 [0 1][57000 -57000 57000][1 0 0 0 1 0 0 0 1]"));
  EXPECT_TRUE(parse_dtrack("6d 1 [0 1][0 0 -100000][1 0 0 0 1 0 0 0 1]"));
}

// A valid DTrack frame of about `bytes` bytes: body 4 and as many others as fit.
std::string large_frame(std::uint64_t frame, std::size_t bytes) {
  std::string bodies;
  int count = 1;
  bodies +=
      " [4 1.000][100.000 1600.000 0.000][1.000000 0.000000 0.000000 0.000000 1.000000 0.000000 0.000000 "
      "0.000000 1.000000]";
  while (bodies.size() + 200 < bytes && count < static_cast<int>(kMaxDTrackBodies)) {
    bodies += " [" + std::to_string(10 + count) +
              " 1.000][-1234.567 2345.678 -3456.789][0.000000 1.000000 0.000000 -1.000000 0.000000 0.000000 "
              "0.000000 0.000000 1.000000]";
    ++count;
  }
  return "fr " + std::to_string(frame) + "\n6d " + std::to_string(count) + bodies + "\n";
}

// The reader hands over every flystick, the newest of each, also from a frame
// without the head's body (which is still counted as such).
TEST(DTrackReader, FlysticksAreTakenNewestFirstWithOrWithoutTheHead) {
  DTrackReader reader(settings(), 10 * kMs);
  TrackerInput in;
  reader.read(
      "fr 1\n6df2 2 2 [0 1.000 6 2][100 200 300][1 0 0 0 1 0 0 0 1][1 0.5 -1.0] "
      "[3 -1.000 6 2][0 0 0][0 0 0 0 0 0 0 0 0][0 0 0]\n",
      5 * kMs, "127.0.0.1", in);
  EXPECT_EQ(in.counted.without_body, 1u) << "no head in it";
  ASSERT_EQ(in.flysticks.size(), 2u);
  EXPECT_TRUE(in.flysticks[0].seen);
  EXPECT_EQ(in.flysticks[0].position, glm::dvec3(100.0, 200.0, 300.0));
  EXPECT_EQ(in.flysticks[0].buttons[0], true);
  EXPECT_EQ(in.flysticks[0].controllers, (std::vector<double>{0.5, -1.0}));
  EXPECT_FALSE(in.flysticks[1].seen) << "quality -1";
  EXPECT_EQ(in.flysticks[1].id, 3u);
  reader.read("fr 2\n6df2 1 1 [0 1.000 6 2][110 200 300][1 0 0 0 1 0 0 0 1][0 0 0]\n", 15 * kMs, "127.0.0.1", in);
  ASSERT_EQ(in.flysticks.size(), 2u) << "one a flystick";
  EXPECT_EQ(in.flysticks[1].id, 0u);
  EXPECT_EQ(in.flysticks[1].arrival, 15 * kMs);
  EXPECT_EQ(in.flysticks[1].position.x, 110.0);
  EXPECT_FALSE(in.empty());
}

// Sixteen hosts each sending valid 36 KB frames as fast as the flood rule lets
// them read (2 kHz), the tracker's 2 KB frames at 60 Hz among them: no more than
// the budget is parsed in any frame, and every frame of the tracker is read.
TEST(DTrackReader, TheReadBudgetBoundsParsingAcrossSendersAndTheTrackerIsRead) {
  const std::string flood = large_frame(1, 36'000);
  ASSERT_GT(flood.size(), 30'000u);
  ASSERT_TRUE(parse_dtrack(flood));
  for (int hosts : {16, 2}) {
    constexpr Nanos kPeriod = 16'666'667;
    DTrackReader reader(settings(), kPeriod);
    std::map<std::uint64_t, std::size_t> parsed_in;  // bytes, by period
    std::uint64_t tracker_samples = 0;
    std::uint64_t tracker_frame = 100;
    for (Nanos t = 0; t < 2'000 * kMs; t += kFloodInterval) {
      for (int h = 0; h < hosts; ++h) {
        TrackerInput in;
        reader.read(flood, t + h * 1'000, "127.0.0." + std::to_string(2 + h), in);
        if (in.counted.flood == 0) parsed_in[static_cast<std::uint64_t>(t / kPeriod)] += flood.size();
      }
      if (t % kPeriod < kFloodInterval) {
        TrackerInput in;
        reader.read(datagram(tracker_frame++, 4, {0, 1600, 0}), t + 200'000, "127.0.0.1", in);
        tracker_samples += in.samples.size();
        if (in.samples.size() == 1) {
          EXPECT_EQ(in.samples[0].sender, "127.0.0.1");
        }
      }
    }
    std::size_t most = 0;
    for (const auto& [period, bytes] : parsed_in) most = std::max(most, bytes);
    EXPECT_LE(most, kReadBudgetBytes) << hosts << " hosts: parsed in one frame";
    EXPECT_EQ(tracker_samples, tracker_frame - 100) << hosts << " hosts: every frame of the tracker read";
    if (hosts == 2) {
      EXPECT_GT(most, 0u) << "two hosts' large frames fit their shares";
    }
  }
}

// DTrack quiet since frames began: said once after kQuietStart, with where the
// master listens; and once more when the first sample comes.
TEST(HeadTracker, ATrackerThatNeverSendsIsSaidWithWhereTheMasterListens) {
  config::Tracking t = settings();
  t.listen = "127.0.0.1";
  t.port = 5017;
  HeadTracker tracker(t);
  std::vector<std::string> said;
  for (Nanos now = 0; now < kQuietStart; now += 100 * kMs) tracker.notice(now, said);
  EXPECT_TRUE(said.empty());
  for (Nanos now = kQuietStart; now < 2 * kQuietStart; now += 100 * kMs) tracker.notice(now, said);
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find("no sample in 2 s"), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("127.0.0.1 port 5017 (UDP)"), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("body 4"), std::string::npos) << said[0];
  EXPECT_FALSE(tracker.datagram(datagram(1, 4, {0, 1600, 0}), 2 * kQuietStart));
  tracker.notice(2 * kQuietStart + 10 * kMs, said);
  tracker.notice(2 * kQuietStart + 20 * kMs, said);
  ASSERT_EQ(said.size(), 2u);
  EXPECT_NE(said[1].find("the first sample came 4000 ms after the first frame"), std::string::npos) << said[1];
  // A tracker that sends from the start is never said to be quiet.
  HeadTracker prompt(t);
  std::vector<std::string> quiet;
  for (Nanos now = 0; now < 2 * kQuietStart; now += 100 * kMs) {
    (void)prompt.datagram(datagram(static_cast<std::uint64_t>(1 + now / (100 * kMs)), 4, {0, 1600, 0}), now);
    prompt.notice(now, quiet);
  }
  EXPECT_TRUE(quiet.empty()) << quiet.front();
}

// A head turning at a constant rate about a tilted axis, from a tilted start:
// constant velocity carries the turn on, exactly; the rate and its direction
// both matter.
TEST(HeadPredictor, ConstantVelocityCarriesTheTurnOnExactly) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 1.0, -0.2));
  const glm::dquat tilt = glm::angleAxis(0.4, glm::normalize(glm::dvec3(1.0, 0.0, 0.5)));
  const double spin = 2.0;  // rad/s
  const auto head = [&](Nanos t) { return glm::angleAxis(spin * static_cast<double>(t) / 1e9, axis) * tilt; };
  HeadPredictor predictor(config::HeadPrediction::constant_velocity, 0.5);
  Nanos t = 0;
  for (int i = 0; i < 10; ++i) {
    t = i * 10 * kMs;
    predictor.add(t, {{}, head(t)});
  }
  for (Nanos ahead : {10 * kMs, 50 * kMs, 150 * kMs}) {
    const glm::dquat p = predictor.predict(t + ahead).orientation;
    EXPECT_LT(glm::angle(p * glm::inverse(head(t + ahead))), 1e-9) << ahead / kMs << " ms ahead";
  }
}

// q and −q are the same turn. A head turning steadily through half a turn (where
// a rotation matrix's quaternion changes sign), and samples given with their
// signs alternating: the prediction turns on smoothly, never the long way round.
TEST(HeadTracker, APredictionAcrossAQuaternionsSignDoesNotSpin) {
  for (auto prediction : {config::HeadPrediction::constant_velocity, config::HeadPrediction::double_exponential}) {
    HeadTracker tracker(settings(prediction));
    std::vector<std::string> said;
    double worst = 0.0;
    // 90° a second about the tracker's z, from 150° to 210° (through 180°).
    for (int i = 0; i < 60; ++i) {
      const Nanos now = i * 10 * kMs;
      const double degrees = 150.0 + 0.9 * i;
      EXPECT_FALSE(tracker.datagram(datagram(1 + i, 4, {0, 1600, 0}, degrees), now));
      if (i < 20) continue;  // double exponential smoothing settles
      const glm::dquat shown = at(tracker, now + 20 * kMs, now, {}, said).pose.orientation;
      const glm::dquat truth = glm::angleAxis(glm::radians(degrees + 1.8), glm::dvec3(0, 0, 1));
      worst = std::max(worst, glm::degrees(glm::angle(glm::dquat(shown * glm::inverse(truth)))));
    }
    EXPECT_LT(worst, 0.5) << config::to_string(prediction);
    // The same turns, every other one given as −q, straight to the predictor.
    HeadPredictor predictor(prediction, 0.7);
    const auto head = [](Nanos t) { return glm::angleAxis(1.5 * static_cast<double>(t) / 1e9, glm::dvec3(0, 1, 0)); };
    Nanos t = 0;
    for (int i = 0; i < 40; ++i) {
      t = i * 10 * kMs;
      predictor.add(t, {{}, i % 2 == 0 ? head(t) : -head(t)});
    }
    const glm::dquat p = predictor.predict(t + 30 * kMs).orientation;
    EXPECT_LT(glm::degrees(glm::angle(glm::dquat(p * glm::inverse(head(t + 30 * kMs))))), 0.5)
        << config::to_string(prediction) << ", signs alternating";
  }
}

// Lost and back: what the predictor knew before the loss is stale. Moving at
// 1 m/s and turning before; back 2 m away, still: the prediction is where the
// head is now, not moved on by a velocity from before (or across) the loss.
TEST(HeadTracker, ThePredictorStartsAgainAfterTheTrackerWasLost) {
  for (auto prediction : {config::HeadPrediction::constant_velocity, config::HeadPrediction::double_exponential}) {
    config::Tracking t = settings(prediction);
    t.lost_after = std::chrono::milliseconds(100);
    HeadTracker tracker(t);
    std::vector<std::string> said;
    std::uint64_t frame = 1;
    for (int i = 0; i < 30; ++i) {
      EXPECT_FALSE(tracker.datagram(datagram(frame++, 4, {10.0 * i, 1600, 0}, 2.0 * i), i * 10 * kMs));
    }
    EXPECT_EQ(at(tracker, 500 * kMs, 500 * kMs, {}, said).state, TrackerState::holding);
    for (int i = 0; i < 3; ++i) {
      EXPECT_FALSE(tracker.datagram(datagram(frame++, 4, {2000, 1600, 0}, 90.0), (600 + 10 * i) * kMs));
    }
    const HeadAt back = at(tracker, 670 * kMs, 620 * kMs, {}, said);
    EXPECT_EQ(back.state, TrackerState::tracking);
    EXPECT_LT(glm::distance(back.pose.position, glm::dvec3(2.0, 1.6, 0.0)), 1e-9) << config::to_string(prediction);
    const glm::dquat still = glm::angleAxis(glm::radians(90.0), glm::dvec3(0, 0, 1));
    EXPECT_LT(glm::angle(glm::dquat(back.pose.orientation * glm::inverse(still))), 1e-6)
        << config::to_string(prediction);
  }
}

TEST(Replay, ParsesRowsAfterAHeaderAndRefusesBadOnes) {
  const auto parsed =
      parse_replay("time,x,y,z,qw,qx,qy,qz\n# a comment\n0, 0,1.6,0, 1,0,0,0\n\n0.5,0.1,1.6,0,1,0,0,0\n", "head.csv");
  ASSERT_TRUE(parsed) << parsed.error();
  ASSERT_EQ(parsed.value().size(), 2u);
  EXPECT_DOUBLE_EQ(parsed.value()[1].position.x, 0.1);
  const struct {
    const char* text;
    const char* says;
  } bad[] = {
      {"0,0,0,0,1,0,0\n", "head.csv:1: 7 fields"},
      {"0,0,0,0,2,0,0,0\n", "head.csv:1: qw, qx, qy, qz is not a unit quaternion"},
      {"0,0,0,0,1,0,0,0\n0,0,0,0,1,0,0,0\n", "head.csv:2: times must increase"},
      {"t,x\n0,nan,0,0,1,0,0,0\n", "head.csv:2: x is not a finite number"},
      {"time\n", "head.csv: no samples"},
  };
  for (const auto& b : bad) {
    const auto refused = parse_replay(b.text, "head.csv");
    ASSERT_FALSE(refused) << b.text;
    EXPECT_NE(refused.error().find(b.says), std::string::npos) << refused.error();
  }
  EXPECT_FALSE(load_replay("/nonexistent/head.csv"));
}

TEST(Replay, TheFeedLoopsAtItsTimes) {
  config::Tracking t = settings();
  t.source = config::TrackingSource::replay;
  HeadTracker tracker(t);
  const auto samples = parse_replay("0,0,0,0,1,0,0,0\n0.1,1,0,0,1,0,0,0\n", "loop.csv");
  ASSERT_TRUE(samples);
  ReplayFeed feed(samples.value(), 1000 * kMs);
  std::vector<std::string> said;
  feed.feed(999 * kMs, tracker);
  EXPECT_EQ(tracker.counts().samples, 0u);
  feed.feed(1150 * kMs, tracker);  // 0 and 0.1 s
  EXPECT_EQ(tracker.counts().samples, 2u);
  EXPECT_DOUBLE_EQ(at(tracker, 1150 * kMs, 1150 * kMs, {}, said).pose.position.x, 1.0);
  feed.feed(1200 * kMs, tracker);  // a loop is 0.2 s: the first again
  EXPECT_EQ(tracker.counts().samples, 3u);
  EXPECT_DOUBLE_EQ(at(tracker, 1200 * kMs, 1200 * kMs, {}, said).pose.position.x, 0.0);
}

TEST(TrackingConfig, EveryProblemIsNamed) {
  schema::Tracking t;
  t.set_source("optitrack");
  t.set_listen("not-an-address");
  t.set_smoothing(1.0);
  t.set_latency_ms(900.0);
  t.add_eye_offset(0.0);
  t.add_eye_offset(2.0);
  t.add_eye_offset(0.0);
  for (double v : {1.0, 0.0, 0.0}) t.mutable_tracker_axes()->add_x(v);
  for (double v : {0.0, 0.0, 1.0}) t.mutable_tracker_axes()->add_y(v);
  for (double v : {0.0, 1.0, 0.0}) t.mutable_tracker_axes()->add_z(v);  // left-handed
  std::vector<config::Problem> problems;
  (void)config::parse_tracking(t, "viewer.tracking", problems);
  std::string all;
  for (const auto& p : problems) all += p.path + ": " + p.message + "\n";
  for (const char* says :
       {"viewer.tracking.source: must be dtrack or replay (got 'optitrack')",
        "viewer.tracking.listen: 'not-an-address' is not an IPv4 or IPv6 address",
        "viewer.tracking.smoothing: must be in (0, 1)", "viewer.tracking.latency_ms: must be 0…500",
        "viewer.tracking.eye_offset: is in metres", "viewer.tracking.tracker_axes: must be right-handed"}) {
    EXPECT_NE(all.find(says), std::string::npos) << says << "\n" << all;
  }
  schema::Tracking replay;
  replay.set_source("replay");
  problems.clear();
  (void)config::parse_tracking(replay, "viewer.tracking", problems);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].path, "viewer.tracking.file");
}

}  // namespace
}  // namespace optique::tracking
