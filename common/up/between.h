#pragma once
// What a frame between key frames is built from (frame-rate up-conversion,
// config/up_conversion.h): the key frames kept, each with the scene state and
// view it was drawn with, and how the frame between takes their pixels. Plain
// values, no GL.

#include <cstdint>

#include <glm/mat4x4.hpp>

#include "config/up_conversion.h"
#include "scene/state.h"

namespace optique::up {

// How a kept key frame was drawn: objects `fraction` of the way from their
// poses in `state` to the next, seen through `view_projection`.
struct KeyView {
  scene::SceneState state;
  double fraction = 0.0;
  glm::dmat4 view_projection{1.0};
};

// motion: each pixel from where its surface was in the key frames (exact, per
// pixel); average: the same pixel of both key frames, half each (the up-
// conversion paper's baseline, which knows nothing of motion).
using BetweenMethod = config::UpMethod;

// Key frames kept at most: the two a frame between is built from, and one being
// drawn a band a frame (config::UpConversion::spread).
inline constexpr int kKeySlots = 3;

// A surface turned further than this (radians) since a key frame faces the
// lights and the eye otherwise than the key frame shaded it: its pixels there
// are not taken; where no key frame has it turned less, it is shaded anew.
inline constexpr double kMostTurn = 0.35;  // 20°

struct BetweenFrame {
  BetweenMethod method = BetweenMethod::motion;
  // Key slot `first` alone (extrapolation from the past), or it and slot
  // `second`, the later key frame, weighing `toward_second` (the frame's time
  // between the two, 0…1).
  int first = 0;
  bool two_keys = false;
  double toward_second = 0.0;
  // Pixels whose surface no key frame saw (disoccluded, or an object that was
  // not there) shaded anew; otherwise they show key `first`'s pixel there,
  // as a repeated frame would (what shading anew is worth, in tests).
  bool shade_unseen = true;
  int second = 1;  // with two_keys
  // How far toward_second moves in one display frame period (1 / the key
  // frames' span): a moment within the frame (a colour field) weighs by its own.
  double per_frame = 0.0;
};

struct BetweenReport {
  // Not seen by any key frame used (motion only); multisampled, the unseen
  // samples in pixels' worth, rounded up.
  std::int64_t unseen_pixels = 0;
  double unseen_share = 0.0;  // of the image's pixels (samples)
};

}  // namespace optique::up
