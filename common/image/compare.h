#pragma once
// Comparing two images of the same size: PSNR per channel, of luma, and the
// up-conversion paper's weighting (PSNR_Y = 0.299·PSNR_R + 0.587·PSNR_G + 0.114·PSNR_B), the
// largest absolute difference, and a difference image to look at.

#include <functional>
#include <limits>

#include "image/image.h"
#include "util/result.h"

namespace optique::image {

struct Comparison {
  double psnr_r = 0.0;  // dB; +infinity when identical
  double psnr_g = 0.0;
  double psnr_b = 0.0;
  double psnr_luma = 0.0;        // of Rec. 601 luma, 0.299 R + 0.587 G + 0.114 B
  double psnr_y_weighted = 0.0;  // 0.299·PSNR_R + 0.587·PSNR_G + 0.114·PSNR_B, the up-conversion paper's PSNR_Y
  double max_abs_error = 0.0;
};

// RGB of both images (alpha ignored); `peak` is the largest possible value.
[[nodiscard]] Result<Comparison> compare(const FloatImage& a, const FloatImage& b, double peak = 1.0);

// The up-conversion paper's local measure: PSNR_Y of each 4×4 block, each
// block in a quality class. The classes' bounds are ours (dB): below 20 "very
// bad", 20–30 "bad", 30–40 "good", 40 and above "better than good". A
// channel identical in a block counts as 100 dB there. Blocks cut by the
// image's edge count as they are.
struct BlockClasses {
  static constexpr double kBounds[3] = {20.0, 30.0, 40.0};
  double share[4] = {0.0, 0.0, 0.0, 0.0};  // very bad, bad, good, better than good; sums to 1
  double worst_db = 0.0;                   // the worst block's PSNR_Y
};
[[nodiscard]] Result<BlockClasses> block_classes(const FloatImage& a, const FloatImage& b, int block = 4,
                                                 double peak = 1.0);

// Rec. 601 luma, 0.299 R + 0.587 G + 0.114 B, of one pixel.
[[nodiscard]] double luma(const FloatImage& image, int x, int y);

// PSNR of luma (dB, `peak`) over the pixels `where` accepts: e.g. a screen's
// usable area. +infinity when they agree there (or no pixel is accepted).
[[nodiscard]] double psnr_luma_where(const FloatImage& a, const FloatImage& b,
                                     const std::function<bool(int x, int y)>& where, double peak = 1.0);

// |a − b| per RGB channel, scaled by `gain`, alpha 1. Sizes must match.
[[nodiscard]] FloatImage difference(const FloatImage& a, const FloatImage& b, float gain = 1.0f);

// Copies `source` into `target` with its top-left corner at (x, y).
void paste(FloatImage& target, const FloatImage& source, int x, int y);

// The `width` × `height` part of `source` whose top-left corner is (x, y); it
// must lie inside `source`.
[[nodiscard]] FloatImage crop(const FloatImage& source, int x, int y, int width, int height);

}  // namespace optique::image
