#pragma once
// The screen simulator: what a screen receives from the projectors that light it.
// Each projector's emitted image (linear light, exactly what leaves the lens:
// blend weights and mask already applied) lands on the screen through its
// homography; light adds in linear space. The result is a raster of the screen at
// `pixels_per_metre`, the same size and pixel positions as a reference render:
// width round(width·ppm), height round(height·ppm); output pixel (u, v) has its
// centre at screen point X = (u + ½)/ppm, Y = height − (v + ½)/ppm.
//
// Each output pixel holds the average light over its footprint (a box), found by
// n × n subsamples of the bilinear reconstruction of each projector image (pixel
// centres at half-integers, zero outside the image).

#include <span>

#include "geometry/projector_geometry.h"
#include "image/image.h"

namespace optique::optics {

// One projector's contribution: where it lands and what it emits (RGB or RGBA,
// linear; alpha is ignored). Both must outlive the call; the image must be the
// geometry's width × height.
struct ProjectedImage {
  const geometry::ProjectorGeometry* geometry = nullptr;
  const image::FloatImage* image = nullptr;
};

struct ComposeOptions {
  double pixels_per_metre = 200.0;
  // Subsamples per output pixel and axis; 0 = from each projector's pixel density
  // (subsamples_for).
  int subsamples = 0;
};

// The screen's raster size along one axis: round(metres · ppm), as render-reference.
[[nodiscard]] int screen_pixels(double metres, double pixels_per_metre);

// Enough subsamples per axis to see every projector pixel about twice across an
// output pixel, at the projector's densest: ceil(2 · density / ppm), in [1, 16].
[[nodiscard]] int subsamples_for(const geometry::ProjectorGeometry& geometry, double pixels_per_metre);

// The light a screen of `width` × `height` metres receives, RGBA (alpha 1),
// linear. Projectors may be empty (a black screen).
[[nodiscard]] image::FloatImage compose_screen(std::span<const ProjectedImage> projectors, double width, double height,
                                               const ComposeOptions& options);

}  // namespace optique::optics
