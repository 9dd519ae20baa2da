#pragma once
// What a FrameBegin carries besides the change of the scene, decoded and checked
// at the edge as the welcome is (welcome.h): the focus, a new share of the
// lights, the scene of a later frame sent ahead. The node applies the change
// to its scene itself (it holds the scene).

#include <cstdint>
#include <optional>

#include "clock/clock.h"
#include "optique/wire.pb.h"
#include "protocol/focus.h"
#include "protocol/light_share.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::protocol {

struct FrameMessage {
  std::uint64_t frame_id = 0;
  clock::Nanos simulation_time = 0;
  clock::Nanos present_time = 0;  // predicted, master clock
  bool capture = false;
  bool skip = false;  // the node is behind: keep what the frame carries, draw nothing
  std::optional<Focus> focus;
  std::optional<LightShare> lights;  // from this frame on
  // The scene of frame ahead_frame (1…config::kMostFramesAhead frames on).
  std::optional<scene::SceneState> ahead;
  std::uint64_t ahead_frame = 0;
};

// Fails, naming the frame and what is wrong, on a focus that is not finite, a
// share naming a light the scene has not (`light_count` lights), or a scene
// sent ahead that is not for 1…kMostFramesAhead frames on or does not decode.
[[nodiscard]] Result<FrameMessage> decode_frame_begin(const wire::FrameBegin& begin, std::uint32_t light_count);

}  // namespace optique::protocol
