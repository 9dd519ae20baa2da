#pragma once
// What a single-chip DLP projector's frame is drawn from (config/color_fields.h):
// one pass per field (per-field), or one render and the fields gathered from it
// along the motion (gather). Plain values, no GL.

#include <vector>

#include <glm/mat4x4.hpp>

#include "render/viewpoint.h"

namespace optique::render {

// One colour field's pass (config/color_fields.h): the channels it writes, and
// the moment it shows.
struct FieldPass {
  Viewpoint view;
  bool red = false;
  bool green = false;
  bool blue = false;
};

// One field of the frame: the channels it shows and its moment, in frame
// periods after the rendered one.
struct GatherField {
  bool red = false;
  bool green = false;
  bool blue = false;
  double shift = 0.0;
};

struct GatherSettings {
  int samples = 8;                  // candidates per field and pixel, ≥ 2
  double velocity_threshold = 0.0;  // pixels per frame period; 0: none
  // The frame's first and last moment as shifts (motion blur above the threshold).
  double frame_start = -0.5;
  double frame_end = 0.5;
};

// Between these fractions of the velocity threshold a pixel goes from field
// offsets to motion blur gradually: a speed that wavers across the threshold
// does not make the image jump from frame to frame.
inline constexpr double kBlurBandFrom = 0.8;
inline constexpr double kBlurBandTo = 1.2;

// What one gather found.
struct GatherReport {
  double fastest = 0.0;    // the fastest screen velocity drawn, pixels per frame period
  bool clamped = false;    // some field moved a surface farther than kGatherRadius: cut short
  int gathered_tiles = 0;  // of kGatherRadius² pixels; the others show the render as it is
};

// The farthest a field moves a surface (pixels): also the tile size.
inline constexpr int kGatherRadius = 20;
inline constexpr int kMaxGatherFields = 3;

// A single-chip DLP projector's frame by the gather method: the scene drawn once
// at `seen`'s moment with each surface's screen velocity between the display
// time and a frame later (each moment seen from where the eye is then), and the
// fields gathered from that image.
struct GatherFrame {
  Viewpoint seen;
  glm::dmat4 view_projection_now{1.0};
  glm::dmat4 view_projection_next{1.0};
  std::vector<GatherField> fields;  // shifts from seen.fraction
  GatherSettings settings;
};

}  // namespace optique::render
