#pragma once
// A projector's job: the part of an installation that one node needs to draw its
// projector. The master cuts it out (job_for) and sends it in its welcome; the
// node parses it back (parse_job); tests and benches cut it out the same way.

#include <cstddef>

#include "config/installation.h"

namespace optique::config {

struct ProjectorJob {
  // Its screen (the only one), the projectors it blends with (itself among them:
  // the same screen, eye and share of the light), the viewer, the scene, and the
  // depth of field's range and inset (the focal depth comes with each frame).
  Installation installation;
  std::size_t projector = 0;  // which of installation.projectors this job draws

  [[nodiscard]] const Projector& self() const { return installation.projectors[projector]; }
  [[nodiscard]] const Screen& screen() const { return installation.screens.front(); }
};

[[nodiscard]] ProjectorJob job_for(const Installation& installation, std::size_t projector);

// The same projector with `factor` times as many pixels along each axis (rounded)
// over the same part of its screen: the homography says where it lands.
void scale_pixels(Projector& projector, double factor);

// The same projector with factor² as many pixels over the same part of the
// screen: references and measurements finer than a pixel.
[[nodiscard]] ProjectorJob supersampled(ProjectorJob job, int factor);

}  // namespace optique::config
