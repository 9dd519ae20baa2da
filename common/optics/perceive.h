#pragma once
// What an eye sees on a screen while it follows something moving: the light each
// projector puts on the screen, channel by channel while that channel is on,
// integrated on the retina over an exposure. A single-chip DLP projector shows its
// colour fields one after another, so a tracked object's channels land apart on
// the retina unless each was drawn for its own moment (Lancelle, Voß & Fellner).
//
// Coordinates are those of a screen raster (optics/compose.h: pixel centres at
// half-integers, y down); the retina is aligned with it at the exposure's centre
// and moves with the tracked velocity.

#include <span>

#include <glm/vec2.hpp>

#include "image/image.h"

namespace optique::optics {

// One projector's light on the screen for one frame, in one time window.
struct Emission {
  // The frame's light on the screen raster (linear RGB or RGBA), averaged over
  // the frame as the projector's signal asks for it. Must outlive the call.
  const image::FloatImage* light = nullptr;
  bool red = true;  // the channels on during the window
  bool green = true;
  bool blue = true;
  double start = 0.0;  // seconds, on the scene's clock
  double end = 0.0;
  // The share of each frame those channels are on (the durations of their
  // fields in all the frame's images; 1 without fields): while on they emit
  // light / on_fraction, so a still image looks the same whatever its fields.
  double on_fraction = 1.0;
};

struct Exposure {
  double centre = 0.0;       // seconds: the retina is aligned with the screen then
  double duration = 0.0;     // seconds, > 0
  glm::dvec2 velocity{0.0};  // the eye's, screen pixels per second (x right, y down)
};

// The light the eye integrates over the exposure, divided by its duration (so a
// still image, still eye, gives the image back), `width` × `height`, RGBA with
// alpha 1. Light from outside the raster is black. Each window's light is
// averaged along the segment the eye moves over it, at two samples per pixel of
// travel or more (bilinear).
[[nodiscard]] image::FloatImage perceive(std::span<const Emission> emissions, int width, int height,
                                         const Exposure& exposure);

// How far apart the channels' edges are in `image` within the box [x0, x1) ×
// [y0, y1), in pixels: along each row (`along_x`; else each column), every edge
// that all three channels have, where each crosses half its brightest value in
// the box (sub-pixel, between pixel centres); the mean over those edges of the
// largest distance between the channels' crossings. 0 without fringes.
[[nodiscard]] double fringe_width(const image::FloatImage& image, int x0, int y0, int x1, int y1, bool along_x = true);

}  // namespace optique::optics
