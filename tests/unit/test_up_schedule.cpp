// Which display frames an up-converting projector draws in full and how it
// builds the others (up/schedule.h): the ratio, cuts, the adaptive ratio and
// the key frames drawn ahead for interpolation.

#include "up/schedule.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

namespace optique::up {
namespace {

config::UpConversion settings(int ratio, config::UpMode mode = config::UpMode::extrapolate, double min_psnr = 0.0,
                              bool spread = false) {
  config::UpConversion s;
  s.ratio = ratio;
  s.mode = mode;
  s.min_psnr = min_psnr;
  s.spread = spread;
  return s;
}

// A walking viewer: 1.2 m/s at 60 Hz.
scene::SceneState state_at(std::uint64_t frame) {
  scene::SceneState state;
  state.eye_now = {0.02 * static_cast<double>(frame), 1.6, 2.0};
  state.eye_next = {0.02 * static_cast<double>(frame + 1), 1.6, 2.0};
  return state;
}

// The plans' kinds in a line: K (drawn now), A<frame> (drawn ahead) then B
// (between), B1/B2 (from one or two key frames), S (shown as drawn ahead);
// |<index> a band of a spread key frame, ! its last.
std::string kinds(UpSchedule& schedule, std::uint64_t from, std::uint64_t to,
                  const std::map<std::uint64_t, scene::SceneState>& states = {}) {
  std::string out;
  const auto state = [&](std::uint64_t f) {
    const auto found = states.find(f);
    return found == states.end() ? state_at(f) : found->second;
  };
  std::map<std::uint64_t, scene::SceneState> sent;
  for (std::uint64_t f = from; f <= to; ++f) {
    // The master sends each frame the state frames_ahead() frames ahead.
    const std::uint64_t ahead = f + static_cast<std::uint64_t>(std::max(1, schedule.settings().frames_ahead()));
    sent[ahead] = state(ahead);
    const UpPlan p = schedule.plan(f, state(f), [&](std::uint64_t g) -> const scene::SceneState* {
      const auto found = sent.find(g);
      return found == sent.end() ? nullptr : &found->second;
    });
    if (!out.empty()) out += ' ';
    if (p.draw_key && !p.ahead_frame) out += 'K';
    if (p.ahead_frame) out += "A" + std::to_string(*p.ahead_frame);
    if (p.between) out += p.frame.two_keys ? "B2" : "B1";
    if (p.shown_slot) out += 'S';
    if (p.band) out += "|" + std::to_string(p.band->index) + (p.band->last() ? "!" : "");
  }
  return out;
}

TEST(UpSchedule, ExtrapolatesFromAKeyFrameEveryRatioFrames) {
  UpSchedule schedule(settings(4));
  EXPECT_EQ(kinds(schedule, 0, 9), "K B1 B1 B1 K B1 B1 B1 K B1");
  UpSchedule again(settings(4));
  const UpPlan first = again.plan(0, state_at(0));
  EXPECT_EQ(first.why, "first frame");
  EXPECT_FALSE(first.check_slot) << "nothing to check against: the ratio is fixed";
  const UpPlan second = again.plan(1, state_at(1));
  EXPECT_EQ(second.frame.first, first.key_slot);
  EXPECT_FALSE(second.frame.two_keys);
}

TEST(UpSchedule, ALightSwitchedOrTheViewerJumpingIsACut) {
  std::map<std::uint64_t, scene::SceneState> states;
  for (std::uint64_t f = 2; f <= 9; ++f) states[f] = state_at(f), states[f].lights_off = {3};
  UpSchedule schedule(settings(4));
  EXPECT_EQ(kinds(schedule, 0, 7, states), "K B1 K B1 B1 B1 K B1");
  UpSchedule jumps(settings(4));
  (void)jumps.plan(0, state_at(0));
  scene::SceneState far = state_at(1);
  far.eye_now.z += kCutEyeJump * 1.1;
  EXPECT_EQ(jumps.plan(1, far).why, "viewer jumped");
  scene::SceneState near = state_at(2);
  near.eye_now.z += kCutEyeJump * 0.9;
  EXPECT_TRUE(jumps.plan(2, near).between);
  // A light an application adds, moves or removes shades every surface anew.
  UpSchedule lit(settings(4));
  (void)lit.plan(0, state_at(0));
  scene::SceneState added = state_at(1);
  added.point_lights[4] = {{0.0, 1.0, 0.0}, {1.0, 1.0, 1.0}, 1.0};
  EXPECT_EQ(lit.plan(1, added).why, "lights added or changed");
  scene::SceneState same = state_at(2);
  same.point_lights = added.point_lights;
  EXPECT_TRUE(lit.plan(2, same).between);
  scene::SceneState moved = state_at(3);
  moved.point_lights = added.point_lights;
  moved.point_lights[4].position.x = 0.5;
  EXPECT_TRUE(lit.plan(3, moved).draw_key);
}

TEST(UpSchedule, FramesThatGoBackOrSkipStartOver) {
  UpSchedule schedule(settings(4));
  (void)schedule.plan(10, state_at(10));
  EXPECT_TRUE(schedule.plan(11, state_at(11)).between);
  EXPECT_TRUE(schedule.plan(5, state_at(5)).draw_key);
  EXPECT_TRUE(schedule.plan(20, state_at(20)).draw_key);
}

TEST(UpSchedule, ForgettingOrGoingBackStartsOver) {
  UpSchedule schedule(settings(4, config::UpMode::interpolate));
  EXPECT_EQ(kinds(schedule, 0, 2), "K A4B2 B2");
  schedule.forget();  // another share of the lights: the kept key frames show the old one
  const UpPlan now = schedule.plan(3, state_at(3));
  EXPECT_TRUE(now.draw_key);
  EXPECT_FALSE(now.ahead_frame);
  EXPECT_EQ(now.why, "first frame");
  // A new run from frame 0: the key drawn ahead for frame 4 of the old run is gone.
  UpSchedule again(settings(4, config::UpMode::interpolate));
  EXPECT_EQ(kinds(again, 0, 2), "K A4B2 B2");
  EXPECT_EQ(kinds(again, 0, 2), "K A4B2 B2") << "frames that go back start over";
  const UpPlan key = again.plan(0, state_at(0));
  ASSERT_NE(key.key_state, nullptr);
  EXPECT_EQ(*key.key_state, state_at(0));
}

TEST(UpSchedule, TheCheckWeighsOnlyAWholeInterval) {
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 30.0));
  (void)schedule.plan(0, state_at(0));
  const UpPlan skipped = schedule.plan(6, state_at(6));  // frames 1–5 never came
  EXPECT_TRUE(skipped.draw_key);
  EXPECT_FALSE(skipped.check_slot) << "six frames on says nothing of a four-frame interval";
  for (std::uint64_t f = 7; f < 10; ++f) (void)schedule.plan(f, state_at(f));
  EXPECT_TRUE(schedule.plan(10, state_at(10)).check_slot);
}

TEST(UpSchedule, TheAdaptiveRatioFollowsTheCheckedError) {
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 30.0));
  (void)schedule.plan(0, state_at(0));
  for (std::uint64_t f = 1; f < 4; ++f) (void)schedule.plan(f, state_at(f));
  const UpPlan key = schedule.plan(4, state_at(4));
  ASSERT_TRUE(key.draw_key);
  ASSERT_TRUE(key.check_slot) << "the frame between from the last key frame is checked against this one";
  EXPECT_EQ(schedule.ratio(), 4);
  schedule.checked(25.0);
  EXPECT_EQ(schedule.ratio(), 3);
  schedule.checked(29.9);
  schedule.checked(29.9);
  schedule.checked(29.9);
  EXPECT_EQ(schedule.ratio(), 1) << "every frame drawn, never fewer";
  EXPECT_EQ(kinds(schedule, 5, 7), "K K K");
  schedule.checked(31.0);
  EXPECT_EQ(schedule.ratio(), 1) << "within the margin: stays";
  schedule.checked(30.0 + kRaiseMargin);
  EXPECT_EQ(schedule.ratio(), 2);
  for (int i = 0; i < 5; ++i) schedule.checked(1e9);
  EXPECT_EQ(schedule.ratio(), 4) << "never beyond the configured ratio";
  UpSchedule fixed(settings(4));
  fixed.checked(10.0);
  EXPECT_EQ(fixed.ratio(), 4);
}

TEST(UpSchedule, InterpolatesBetweenAKeyFrameAndOneDrawnAhead) {
  UpSchedule schedule(settings(4, config::UpMode::interpolate));
  EXPECT_EQ(kinds(schedule, 0, 9), "K A4B2 B2 B2 S A8B2 B2 B2 S A12B2");
  UpSchedule again(settings(4, config::UpMode::interpolate));
  std::map<std::uint64_t, scene::SceneState> ahead{{4, state_at(4)}};
  const auto lookup = [&](std::uint64_t f) -> const scene::SceneState* {
    return ahead.contains(f) ? &ahead[f] : nullptr;
  };
  const UpPlan a = again.plan(0, state_at(0), lookup);
  const UpPlan b = again.plan(1, state_at(1), lookup);
  EXPECT_NE(b.key_slot, a.key_slot);
  EXPECT_EQ(b.frame.first, a.key_slot);
  EXPECT_DOUBLE_EQ(b.frame.toward_second, 0.25);
  EXPECT_DOUBLE_EQ(b.frame.per_frame, 0.25) << "a colour field a frame later would weigh 0.5";
  EXPECT_DOUBLE_EQ(again.plan(3, state_at(3), lookup).frame.toward_second, 0.75);
  EXPECT_EQ(again.plan(4, state_at(4), lookup).shown_slot, b.key_slot);
  const UpPlan c = again.plan(5, state_at(5), lookup);
  EXPECT_EQ(c.why, "nothing ahead");
}

TEST(UpSchedule, InterpolationTakesWhatTheMasterSentAhead) {
  UpSchedule schedule(settings(4, config::UpMode::interpolate));
  std::map<std::uint64_t, scene::SceneState> ahead{{2, state_at(2)}};
  const auto lookup = [&](std::uint64_t f) -> const scene::SceneState* {
    return ahead.contains(f) ? &ahead[f] : nullptr;
  };
  (void)schedule.plan(0, state_at(0), lookup);
  const UpPlan p = schedule.plan(1, state_at(1), lookup);
  ASSERT_TRUE(p.ahead_frame);
  EXPECT_EQ(*p.ahead_frame, 2u) << "the farthest sent within the ratio";
  EXPECT_DOUBLE_EQ(p.frame.toward_second, 0.5);
}

TEST(UpSchedule, NoFrameBetweenMixesTheTwoSidesOfACut) {
  std::map<std::uint64_t, scene::SceneState> states;
  for (std::uint64_t f = 3; f <= 12; ++f) states[f] = state_at(f), states[f].lights_off = {0};
  UpSchedule schedule(settings(4, config::UpMode::interpolate));
  // Frames 1 and 2 from key 0 alone, 3 from key 4 alone.
  EXPECT_EQ(kinds(schedule, 0, 5, states), "K A4B1 B1 B1 S A8B2");
  UpSchedule check(settings(4, config::UpMode::interpolate));
  std::map<std::uint64_t, scene::SceneState> sent{{4, states[4]}};
  const auto lookup = [&](std::uint64_t f) -> const scene::SceneState* {
    return sent.contains(f) ? &sent[f] : nullptr;
  };
  const UpPlan a = check.plan(0, state_at(0), lookup);
  const UpPlan one = check.plan(1, state_at(1), lookup);
  EXPECT_EQ(one.frame.first, a.key_slot);
  EXPECT_FALSE(one.frame.two_keys);
  const UpPlan three = check.plan(3, states[3], lookup);
  EXPECT_EQ(three.frame.first, one.key_slot) << "after the switch: the key frame drawn ahead";
  EXPECT_FALSE(three.frame.two_keys);
}

// Spread, extrapolated: the key frame of a frame is drawn a band a frame over it
// and the next ratio − 1 frames, then used; every frame between draws a band,
// into a slot no frame between reads.
TEST(UpSchedule, SpreadKeyFramesAreDrawnABandAFrame) {
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 0.0, true));
  EXPECT_EQ(schedule.slots(), 3);
  EXPECT_EQ(kinds(schedule, 0, 10), "K B1|0 B1|1 B1|2 B1|3! B1|0 B1|1 B1|2 B1|3! B1|0 B1|1");
  UpSchedule again(settings(4, config::UpMode::extrapolate, 0.0, true));
  const UpPlan key = again.plan(0, state_at(0));
  std::vector<UpPlan> plans;
  for (std::uint64_t f = 1; f <= 9; ++f) plans.push_back(again.plan(f, state_at(f)));
  for (const UpPlan& p : plans) {
    ASSERT_TRUE(p.band);
    EXPECT_NE(p.band->slot, p.frame.first) << "a band never lands in the key frame a frame between reads";
  }
  EXPECT_EQ(plans[0].frame.first, key.key_slot);
  EXPECT_EQ(plans[0].band->frame, 1u) << "the key frame of the frame its first band is drawn with";
  EXPECT_EQ(plans[3].frame.first, key.key_slot) << "frame 4 still from frame 0's key frame";
  EXPECT_EQ(plans[4].frame.first, plans[0].band->slot) << "frame 5 from frame 1's, drawn over frames 1-4";
  EXPECT_EQ(plans[8].frame.first, plans[4].band->slot) << "frame 9 from frame 5's";
  // Without spread, two slots.
  EXPECT_EQ(UpSchedule(settings(4)).slots(), 2);
}

// A cut while a key frame is drawn in bands: the key frame is drawn at once and
// the bands begin again from the new side. Frames skipped past twice the ratio
// draw one at once too.
TEST(UpSchedule, ACutOrSkippedFramesBeginTheBandsAgain) {
  std::map<std::uint64_t, scene::SceneState> states;
  for (std::uint64_t f = 3; f <= 12; ++f) states[f] = state_at(f), states[f].lights_off = {1};
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 0.0, true));
  EXPECT_EQ(kinds(schedule, 0, 9, states), "K B1|0 B1|1 K B1|0 B1|1 B1|2 B1|3! B1|0 B1|1");
  EXPECT_EQ(schedule.plan(18, states[12]).why, "ratio") << "frame 4's key frame is 14 frames old";
}

// A frame skipped while a key frame is drawn in bands: the frame it is due with
// draws all the bands it lacks, and the next frame uses it (no key frame at
// once). With the adaptive ratio at 1, every frame is a key frame drawn at once.
TEST(UpSchedule, ASkippedFrameLeavesTheRestOfTheBandsToTheDueFrame) {
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 0.0, true));
  EXPECT_EQ(kinds(schedule, 0, 6), "K B1|0 B1|1 B1|2 B1|3! B1|0 B1|1");
  const UpPlan due = schedule.plan(8, state_at(8));  // frame 7 never came
  ASSERT_TRUE(due.between);
  ASSERT_TRUE(due.band);
  EXPECT_EQ(due.band->index, 2);
  EXPECT_EQ(due.band->bands, 2);
  EXPECT_TRUE(due.band->last());
  const UpPlan next = schedule.plan(9, state_at(9));
  EXPECT_TRUE(next.between) << next.why;
  EXPECT_EQ(next.frame.first, due.band->slot) << "frame 5's key frame, complete";

  UpSchedule interpolating(settings(4, config::UpMode::interpolate, 0.0, true));
  EXPECT_EQ(kinds(interpolating, 0, 9), "K K K K A7B2 B2|0 B2|1 S|2! B2|0 B2|1");
  std::map<std::uint64_t, scene::SceneState> sent;
  for (std::uint64_t f = 10; f <= 18; ++f) sent[f] = state_at(f);
  const auto lookup = [&](std::uint64_t f) -> const scene::SceneState* {
    return sent.contains(f) ? &sent[f] : nullptr;
  };
  const UpPlan shown = interpolating.plan(11, state_at(11), lookup);  // frame 10 never came
  ASSERT_TRUE(shown.shown_slot);
  ASSERT_TRUE(shown.band);
  EXPECT_EQ(shown.band->bands, 2) << "the two bands frame 15's key frame lacks";
  EXPECT_TRUE(shown.band->last());
  EXPECT_TRUE(interpolating.plan(12, state_at(12), lookup).frame.two_keys);

  UpSchedule lowered(settings(4, config::UpMode::extrapolate, 30.0, true));
  (void)lowered.plan(0, state_at(0));
  for (int i = 0; i < 3; ++i) lowered.checked(10.0);
  ASSERT_EQ(lowered.ratio(), 1);
  EXPECT_EQ(kinds(lowered, 1, 3), "K K K") << "every frame drawn at once, not a band of one and a frame between";
}

// Spread, interpolated: the key frame after the next is drawn, from the scene
// sent 2·ratio − 1 frames ahead, over the frames up to the one that shows the
// next. Until the scenes sent ahead reach that far (the first frames), key
// frames are drawn at once.
TEST(UpSchedule, SpreadInterpolationDrawsTheKeyFrameAfterTheNext) {
  UpSchedule schedule(settings(4, config::UpMode::interpolate, 0.0, true));
  EXPECT_EQ(schedule.settings().frames_ahead(), 7);
  EXPECT_EQ(kinds(schedule, 0, 16), "K K K K A7B2 B2|0 B2|1 S|2! B2|0 B2|1 B2|2 S|3! B2|0 B2|1 B2|2 S|3! B2|0");
  UpSchedule again(settings(4, config::UpMode::interpolate, 0.0, true));
  std::map<std::uint64_t, scene::SceneState> sent;
  const auto lookup = [&](std::uint64_t f) -> const scene::SceneState* {
    return sent.contains(f) ? &sent[f] : nullptr;
  };
  std::vector<UpPlan> plans;
  for (std::uint64_t f = 0; f <= 12; ++f) {
    sent[f + 7] = state_at(f + 7);
    plans.push_back(again.plan(f, state_at(f), lookup));
    if (f == 5) {  // the state is the schedule's until the next plan
      ASSERT_TRUE(plans[5].band);
      EXPECT_EQ(plans[5].band->frame, 11u);
      ASSERT_NE(plans[5].band->state, nullptr);
      EXPECT_EQ(plans[5].band->state->eye_now, state_at(11).eye_now);
    }
  }
  for (int f = 8; f <= 10; ++f) {
    ASSERT_TRUE(plans[f].between);
    EXPECT_TRUE(plans[f].frame.two_keys);
    EXPECT_EQ(plans[f].frame.first, plans[4].key_slot) << "frame " << f << " from the key frame shown at 7";
    EXPECT_EQ(plans[f].frame.second, plans[5].band->slot) << "and frame 11's, drawn over frames 5-7";
    EXPECT_NE(plans[f].band->slot, plans[f].frame.first);
    EXPECT_NE(plans[f].band->slot, plans[f].frame.second);
  }
  EXPECT_DOUBLE_EQ(plans[9].frame.toward_second, 0.5);
  EXPECT_EQ(plans[11].shown_slot, plans[5].band->slot);
}

// The adaptive check with spread key frames: with the band that completes one,
// from the key frame a whole interval before it.
TEST(UpSchedule, SpreadKeyFramesAreCheckedWhenComplete) {
  UpSchedule schedule(settings(4, config::UpMode::extrapolate, 30.0, true));
  std::vector<UpPlan> plans;
  for (std::uint64_t f = 0; f <= 8; ++f) plans.push_back(schedule.plan(f, state_at(f)));
  EXPECT_FALSE(plans[4].check_slot) << "frame 1's key frame is one frame after frame 0's";
  ASSERT_TRUE(plans[8].band && plans[8].band->last());
  ASSERT_TRUE(plans[8].check_slot);
  EXPECT_EQ(*plans[8].check_slot, plans[4].band->slot) << "frame 5's key frame against frame 1's";
  schedule.checked(20.0);
  EXPECT_EQ(schedule.ratio(), 3);
  EXPECT_EQ(kinds(schedule, 9, 12), "B1|0 B1|1 B1|2! B1|0") << "the next key frame in three bands";
}

}  // namespace
}  // namespace optique::up
