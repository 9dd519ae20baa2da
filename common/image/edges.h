#pragma once
// Where edges are, compared between two images of the same scene: a composite
// whose projectors disagree shows an edge twice, or moved. For every isolated
// strong edge of the reference (along rows and along columns), the luma
// gradient's centroid in a small window gives the edge's sub-pixel position in
// each image; their difference is the edge's displacement, and the change of the
// gradient's spread says whether the edge got wider (doubled or blurred).

#include <cstddef>
#include <functional>

#include "image/image.h"

namespace optique::image {

struct EdgeShifts {
  std::size_t edges = 0;       // isolated edges measured
  double max_abs_px = 0.0;     // largest |displacement|
  double median_abs_px = 0.0;  // median |displacement|
  // Largest growth of an edge's width (the spread of its gradient): a doubled
  // edge is wider even where its two halves balance and it does not move.
  double max_widening_px = 0.0;
};

struct EdgeOptions {
  double threshold = 0.05;  // smallest central-difference step of linear luma that counts as an edge
  int half_window = 4;      // pixels each side of the edge
  // Which pixels to measure at (default: all); e.g. the overlaps of projectors.
  std::function<bool(int x, int y)> where;
};

// RGB(A) images of equal size.
[[nodiscard]] EdgeShifts edge_shifts(const FloatImage& reference, const FloatImage& test, const EdgeOptions& options);

}  // namespace optique::image
