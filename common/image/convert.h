#pragma once
// Converting images on the CPU: what the renderer's encoding pass does, for
// linear images made elsewhere (composites, downsampled references), and the box
// filter that turns a supersampled render into pixel averages.

#include "image/image.h"

namespace optique::image {

// The sRGB transfer function, as the renderer's encoding pass applies it (RGB
// clamped to [0, 1], rounded to 8 bits; alpha 255): for PNGs of linear images.
[[nodiscard]] ByteImage encode_srgb(const FloatImage& linear);

// Averages each `factor` × `factor` block (box filter, linear light). The size
// must be a multiple of `factor`.
[[nodiscard]] FloatImage box_downsample(const FloatImage& image, int factor);

}  // namespace optique::image
