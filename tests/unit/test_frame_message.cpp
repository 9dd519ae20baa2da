// A FrameBegin as the node takes it (common/protocol/frame_message.h): what the
// master put in comes out as typed values, and what a node cannot use (a focus
// that is not finite, a light the scene has not, a scene sent ahead for a frame
// not 1…kMostFramesAhead on or not a valid snapshot) is refused, naming the
// frame and what is wrong.

#include "protocol/frame_message.h"

#include <gtest/gtest.h>

#include <limits>

#include "config/up_conversion.h"
#include "protocol/welcome.h"
#include "scene/state.h"

namespace optique::protocol {
namespace {

wire::FrameBegin frame(std::uint64_t id) {
  wire::FrameBegin begin;
  begin.set_frame_id(id);
  begin.set_simulation_time_ns(1'000'000);
  begin.set_present_time_ns(2'000'000);
  return begin;
}

void expect_refused(const wire::FrameBegin& begin, std::uint32_t lights, const std::string& says) {
  const auto decoded = decode_frame_begin(begin, lights);
  ASSERT_FALSE(decoded.ok()) << says;
  EXPECT_NE(decoded.error().find("frame " + std::to_string(begin.frame_id()) + ": "), std::string::npos)
      << decoded.error();
  EXPECT_NE(decoded.error().find(says), std::string::npos) << decoded.error();
}

TEST(FrameMessage, WhatTheMasterPutInComesOut) {
  wire::FrameBegin begin = frame(7);
  begin.set_capture(true);
  *begin.mutable_focus() = to_wire(Focus{2.5, {0.25, -0.5}});
  *begin.mutable_lights() = to_wire(LightShare{{0, 3}, true});
  scene::SceneState later;
  later.eye_now = {0.1, 1.7, 2.0};
  *begin.mutable_ahead() = scene::to_snapshot(later);
  begin.set_ahead_frame(7 + config::kMostFramesAhead);
  const auto decoded = decode_frame_begin(begin, 4);
  ASSERT_TRUE(decoded.ok()) << decoded.error();
  const FrameMessage& f = decoded.value();
  EXPECT_EQ(f.frame_id, 7u);
  EXPECT_EQ(f.simulation_time, 1'000'000);
  EXPECT_EQ(f.present_time, 2'000'000);
  EXPECT_TRUE(f.capture);
  EXPECT_FALSE(f.skip);
  ASSERT_TRUE(f.focus.has_value());
  EXPECT_EQ(*f.focus, (Focus{2.5, {0.25, -0.5}}));
  ASSERT_TRUE(f.lights.has_value());
  EXPECT_EQ(*f.lights, (LightShare{{0, 3}, true}));
  ASSERT_TRUE(f.ahead.has_value());
  EXPECT_EQ(*f.ahead, later);
  EXPECT_EQ(f.ahead_frame, 7u + config::kMostFramesAhead);

  const auto plain = decode_frame_begin(frame(8), 0);
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain.value().focus || plain.value().lights || plain.value().ahead) << "only what was sent";
}

TEST(FrameMessage, WhatANodeCannotUseIsRefusedByName) {
  wire::FrameBegin focus = frame(3);
  focus.mutable_focus()->set_depth(std::numeric_limits<double>::quiet_NaN());
  expect_refused(focus, 0, "focus depth");

  wire::FrameBegin lights = frame(4);
  // 4 of the scene's, and those applications may add: 4 + 64 is one too many.
  *lights.mutable_lights() = to_wire(LightShare{{4 + scene::kMaxAddedLights}, false});
  expect_refused(lights, 4, "lights: light 68 does not exist");
  *lights.mutable_lights() = to_wire(LightShare{{3 + scene::kMaxAddedLights}, false});
  EXPECT_TRUE(decode_frame_begin(lights, 4).ok());

  for (const std::uint64_t ahead :
       {std::uint64_t{5}, std::uint64_t{4}, 5 + std::uint64_t(config::kMostFramesAhead) + 1}) {
    wire::FrameBegin sent_ahead = frame(5);
    *sent_ahead.mutable_ahead() = scene::to_snapshot(scene::SceneState{});
    sent_ahead.set_ahead_frame(ahead);
    expect_refused(sent_ahead, 0, "the scene sent ahead is for frame " + std::to_string(ahead));
  }

  wire::FrameBegin broken = frame(6);
  scene::SceneState odd;
  odd.eye_now.x = std::numeric_limits<double>::infinity();
  *broken.mutable_ahead() = scene::to_snapshot(odd);
  broken.set_ahead_frame(7);
  expect_refused(broken, 0, "the scene sent ahead: ");
}

}  // namespace
}  // namespace optique::protocol
