#pragma once
// Optical depth of field (Majumder & Welch, "Computer
// Graphics Optique"; docs/design.md): a focused and a defocused
// projector light the same image area. The focused one shows (1 − c_r)·I, the
// defocused one c_r·I, and the defocused projector's optics blur by the maximum
// circle of confusion, so the sum on the screen approximates an image in which
// each pixel is blurred by its own circle c_r · c_max. This file holds the circle
// of confusion (exact, and in the window-depth form a shader evaluates), the
// defocused projector's blur, and the ideal per-pixel blur used as the reference.
//
// Discs on the pixel grid: the discrete disc D_R (R = 0, 1, 2, …) is the set of
// pixels whose centres lie within R + ½ of the source pixel's centre, i.e.
// dx² + dy² ≤ R(R + 1). A disc of radius r ≤ ½ is D_0 (the pixel itself); for
// R + ½ ≤ r ≤ R + 3/2 the light is split between D_R and D_{R+1} in proportion
// to where r lies between the two, so the image changes continuously with r. Each
// disc spreads its share evenly over its pixels; light landing outside the image
// is lost. Radii above kMaxDiscRadius are treated as kMaxDiscRadius, which bounds
// the cost of absurd inputs.

#include "image/image.h"

namespace optique::optics {

inline constexpr double kMaxDiscRadius = 4096.0;

// The depth range over which the relative circle of confusion grows from 0 to 1.
struct CocRange {
  double near = 0;  // metres from the eye, 0 < near < far
  double far = 0;
};

// Relative radius of confusion of a point at eye depth z when the focal depth is b:
// c_r = |1/b − 1/z| / |1/near − 1/far|, with z and b first clamped to [near, far].
// In [0, 1]; 0 at z = b.
[[nodiscard]] double relative_coc(double z, double b, const CocRange& range);

// Window depth (depth range [0, 1]) of eye depth z > 0 for a perspective frustum:
// z' = f(z − n) / (z(f − n)), 0 at the near plane, 1 at the far plane.
[[nodiscard]] double window_depth(double z, double frustum_near, double frustum_far);

// The circle of confusion from window depth as a depth buffer holds it. 1/z is
// affine in z' (1/z = 1/n − z'(1/n − 1/f)), so c_r = k · |clamp(z', lo, hi) − b'|
// with lo, hi the window depths of range.near and range.far, b' that of the
// (clamped) focal depth and k = (1/n − 1/f) / (1/near − 1/far). A shader
// evaluates exactly this with these four numbers as uniforms.
struct CocFromWindowDepth {
  double k = 0;
  double focal = 0;  // b'
  double lo = 0;
  double hi = 1;
};
[[nodiscard]] CocFromWindowDepth coc_from_window_depth(double b, const CocRange& range, double frustum_near,
                                                       double frustum_far);

// Evaluates the mapping in float, as a shader would; returns min(1, c_r). Float rounding of z' and b' (2^-25 near
// z' = 1) limits it to within about k · 2^-24 of the exact c_r: ~1e-6 for k ≈ 20, ~1e-7 for k = 1.
[[nodiscard]] double relative_coc(float window_depth, const CocFromWindowDepth& mapping);

// A defocused projector's optics: every pixel's light spread evenly over a disc of
// `radius` pixels (see the top of this file). Applies to all channels except a
// 4th (alpha), which is copied. Radius 0 (or anything up to ½) leaves the image
// unchanged. 1 to 4 channels; radius finite and ≥ 0.
[[nodiscard]] image::FloatImage disc_blur(const image::FloatImage& image, double radius);

// The ideal depth-of-field image (the reference): every pixel's light spread over
// a disc of its own radius radius_px(x, y) (1 channel, same size as `image`, in
// pixels, finite and ≥ 0), with the same discs as disc_blur: a constant map r
// gives disc_blur(image, r). Channels as disc_blur. Costs O(radius) per source
// pixel (a per-row difference scatter).
[[nodiscard]] image::FloatImage scatter_defocus(const image::FloatImage& image, const image::FloatImage& radius_px);

}  // namespace optique::optics
