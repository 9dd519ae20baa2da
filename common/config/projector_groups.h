#pragma once
// How projectors of an installation relate: whose light adds into one image,
// which show the same share of it, which blend their overlaps.

#include "config/installation.h"

namespace optique::config {

// Whether two projectors light the same screen for the same eye: their light adds
// into one image, which the screen simulator composes.
[[nodiscard]] bool same_screen_image(const Projector& a, const Projector& b);

// Whether two projectors show the same share of the light (the same content role,
// lights and ambient): a layer of a stacked group, or all projectors of a plain
// wall. Projectors whose lights the master shares out ("auto") are each a layer.
[[nodiscard]] bool same_layer(const Projector& a, const Projector& b);

// Whether two projectors blend their overlaps with each other: the same screen
// image and the same layer. Stacked layers do not blend with each other: their
// light is meant to add.
[[nodiscard]] bool same_blend_group(const Projector& a, const Projector& b);

}  // namespace optique::config
