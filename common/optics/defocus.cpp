#include "optics/defocus.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace optique::optics {
namespace {

[[maybe_unused]] bool valid_range(const CocRange& range) {
  return std::isfinite(range.near) && std::isfinite(range.far) && range.near > 0.0 && range.near < range.far;
}

[[maybe_unused]] bool valid_frustum(double n, double f) {
  return std::isfinite(n) && std::isfinite(f) && n > 0.0 && n < f;
}

// Largest h with h² ≤ n, for 0 ≤ n < 2^52 (the double sqrt can be one off either way).
std::int64_t isqrt(std::int64_t n) {
  auto h = static_cast<std::int64_t>(std::sqrt(static_cast<double>(n)));
  while (h * h > n) --h;
  while ((h + 1) * (h + 1) <= n) ++h;
  return h;
}

// The light of one source pixel: share (1 − t) on D_inner, t on D_{inner+1}.
struct DiscMix {
  int inner = 0;
  double t = 0.0;
};

DiscMix disc_mix(double radius) {
  assert(std::isfinite(radius) && radius >= 0.0);
  // Written so that NaN (a contract violation that asserts cannot catch in release) stays in the pixel.
  if (!(radius > 0.5)) return {};
  const double s = std::min(radius, kMaxDiscRadius) - 0.5;
  const double inner = std::floor(s);
  return {static_cast<int>(inner), s - inner};
}

// Half-widths of the discs' rows: D_R's row dy spans dx ∈ [−h, h] with h = half_width[R][|dy|]. Only the discs
// an image uses are built, so a map of small radii does not pay for one huge one.
class DiscTable {
 public:
  explicit DiscTable(const std::vector<bool>& needed) : half_width_(needed.size()), inv_count_(needed.size(), 0.0) {
    for (std::size_t r = 0; r < needed.size(); ++r) {
      if (!needed[r]) continue;
      const auto big_r = static_cast<std::int64_t>(r);
      std::vector<int>& rows = half_width_[r];
      rows.resize(r + 1);
      double count = 0.0;
      for (std::int64_t dy = 0; dy <= big_r; ++dy) {
        rows[dy] = static_cast<int>(isqrt(big_r * (big_r + 1) - dy * dy));
        count += (dy == 0 ? 1.0 : 2.0) * (2.0 * rows[dy] + 1.0);
      }
      inv_count_[r] = 1.0 / count;
    }
  }

  [[nodiscard]] const std::vector<int>& half_widths(int r) const {
    assert(!half_width_[r].empty());
    return half_width_[r];
  }
  [[nodiscard]] double inv_count(int r) const { return inv_count_[r]; }

 private:
  std::vector<std::vector<int>> half_width_;
  std::vector<double> inv_count_;
};

// Every blurred channel of each source pixel, spread over discs by a difference scatter: a span of constant weight
// along a row is +w at its start and −w one past its end, and a running sum along the row then gives the light at
// each pixel. So a disc costs two writes per row, O(radius) per source pixel instead of O(radius²).
class DiscScatter {
 public:
  explicit DiscScatter(const image::FloatImage& image)
      : image_(image),
        blurred_(image.channels == 4 ? 3 : image.channels),
        stride_(static_cast<std::size_t>(image.width + 1) * blurred_),
        diff_(stride_ * image.height, 0.0) {}

  void add(int x, int y, const DiscMix& mix, const DiscTable& table) {
    const float* source = &image_.at(x, y, 0);
    bool lit = false;
    for (int c = 0; c < blurred_; ++c) lit = lit || source[c] != 0.0f;
    if (!lit) return;
    switch (blurred_) {
      case 1:
        add_discs<1>(x, y, mix, source, table);
        break;
      case 2:
        add_discs<2>(x, y, mix, source, table);
        break;
      default:
        add_discs<3>(x, y, mix, source, table);
        break;
    }
  }

  [[nodiscard]] image::FloatImage result() const {
    image::FloatImage out(image_.width, image_.height, image_.channels);
    for (int y = 0; y < image_.height; ++y) {
      const double* row = diff_.data() + static_cast<std::size_t>(y) * stride_;
      double sum[4] = {0.0, 0.0, 0.0, 0.0};
      for (int x = 0; x < image_.width; ++x) {
        for (int c = 0; c < blurred_; ++c) {
          sum[c] += row[static_cast<std::size_t>(x) * blurred_ + c];
          out.at(x, y, c) = static_cast<float>(sum[c]);
        }
        if (blurred_ < image_.channels) out.at(x, y, 3) = image_.at(x, y, 3);
      }
    }
    return out;
  }

 private:
  // One pass over the rows of the outer disc writes both discs' spans (the inner one is nested in it). The
  // channel count is a template argument so that the per-row work unrolls: it is the whole cost.
  template <int N>
  void add_discs(int x, int y, const DiscMix& mix, const float* source, const DiscTable& table) {
    const int inner = mix.inner;
    const bool blend = mix.t > 0.0;
    const int outer = blend ? inner + 1 : inner;
    const double inner_weight = (1.0 - mix.t) * table.inv_count(inner);
    const double outer_weight = mix.t * table.inv_count(outer);
    double inner_light[N];
    double outer_light[N];
    for (int c = 0; c < N; ++c) {
      inner_light[c] = inner_weight * source[c];
      outer_light[c] = outer_weight * source[c];
    }
    const int* inner_half = table.half_widths(inner).data();
    const int* outer_half = table.half_widths(outer).data();
    const int dy_begin = std::max(-outer, -y);
    const int dy_end = std::min(outer, image_.height - 1 - y);
    const auto stride = static_cast<std::ptrdiff_t>(stride_);
    double* row = diff_.data() + static_cast<std::ptrdiff_t>(y + dy_begin) * stride;
    for (int dy = dy_begin; dy <= dy_end; ++dy, row += stride) {
      const int ady = std::abs(dy);
      if (blend) add_span<N>(row, x, outer_half[ady], outer_light);
      if (ady <= inner) add_span<N>(row, x, inner_half[ady], inner_light);
    }
  }

  template <int N>
  void add_span(double* row, int x, int h, const double* light) const {
    // Light beyond the left or right edge is lost: the span is cut, not shifted.
    double* first = row + static_cast<std::ptrdiff_t>(std::max(0, x - h)) * N;
    double* past = row + static_cast<std::ptrdiff_t>(std::min(image_.width, x + h + 1)) * N;
    for (int c = 0; c < N; ++c) {
      first[c] += light[c];
      past[c] -= light[c];
    }
  }

  const image::FloatImage& image_;
  int blurred_;
  std::size_t stride_;
  // Double: a row's running sum adds and removes every span, and float would leave residue of the bright pixels
  // in the dark ones.
  std::vector<double> diff_;
};

[[maybe_unused]] bool valid_image(const image::FloatImage& image) {
  return image.width >= 0 && image.height >= 0 && image.channels >= 1 && image.channels <= 4 &&
         image.pixels.size() == static_cast<std::size_t>(image.width) * image.height * image.channels;
}

}  // namespace

double relative_coc(double z, double b, const CocRange& range) {
  assert(valid_range(range));
  assert(!std::isnan(z) && !std::isnan(b));
  const double zc = std::clamp(z, range.near, range.far);
  const double bc = std::clamp(b, range.near, range.far);
  return std::min(1.0, std::abs(1.0 / bc - 1.0 / zc) / (1.0 / range.near - 1.0 / range.far));
}

double window_depth(double z, double frustum_near, double frustum_far) {
  assert(valid_frustum(frustum_near, frustum_far));
  assert(z > 0.0);
  return frustum_far * (z - frustum_near) / (z * (frustum_far - frustum_near));
}

CocFromWindowDepth coc_from_window_depth(double b, const CocRange& range, double frustum_near, double frustum_far) {
  assert(valid_range(range));
  assert(valid_frustum(frustum_near, frustum_far));
  assert(!std::isnan(b));
  CocFromWindowDepth mapping;
  mapping.k = (1.0 / frustum_near - 1.0 / frustum_far) / (1.0 / range.near - 1.0 / range.far);
  mapping.focal = window_depth(std::clamp(b, range.near, range.far), frustum_near, frustum_far);
  mapping.lo = window_depth(range.near, frustum_near, frustum_far);
  mapping.hi = window_depth(range.far, frustum_near, frustum_far);
  return mapping;
}

double relative_coc(float window_depth, const CocFromWindowDepth& mapping) {
  assert(mapping.lo <= mapping.hi);
  // The uniforms reach the shader as floats, so they are rounded here too.
  const auto k = static_cast<float>(mapping.k);
  const auto focal = static_cast<float>(mapping.focal);
  const auto lo = static_cast<float>(mapping.lo);
  const auto hi = static_cast<float>(mapping.hi);
  const float z = std::clamp(window_depth, lo, hi);
  const float c = k * std::abs(z - focal);
  return std::min(1.0, static_cast<double>(c));
}

image::FloatImage disc_blur(const image::FloatImage& image, double radius) {
  assert(valid_image(image));
  const DiscMix mix = disc_mix(radius);
  if (mix.inner == 0 && mix.t == 0.0) return image;
  std::vector<bool> needed(static_cast<std::size_t>(mix.inner) + 2, false);
  needed[mix.inner] = true;
  needed[mix.inner + 1] = mix.t > 0.0;
  const DiscTable table(needed);
  DiscScatter scatter(image);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) scatter.add(x, y, mix, table);
  }
  return scatter.result();
}

image::FloatImage scatter_defocus(const image::FloatImage& image, const image::FloatImage& radius_px) {
  assert(valid_image(image));
  assert(radius_px.width == image.width && radius_px.height == image.height && radius_px.channels == 1 &&
         radius_px.pixels.size() == static_cast<std::size_t>(image.width) * image.height);
  std::vector<DiscMix> mixes(radius_px.pixels.size());
  std::vector<bool> needed;
  for (std::size_t i = 0; i < mixes.size(); ++i) {
    mixes[i] = disc_mix(radius_px.pixels[i]);
    const auto outer = static_cast<std::size_t>(mixes[i].inner) + (mixes[i].t > 0.0 ? 1 : 0);
    if (needed.size() <= outer) needed.resize(outer + 1, false);
    needed[mixes[i].inner] = true;
    needed[outer] = true;
  }
  const DiscTable table(needed);
  DiscScatter scatter(image);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      scatter.add(x, y, mixes[static_cast<std::size_t>(y) * image.width + x], table);
    }
  }
  return scatter.result();
}

}  // namespace optique::optics
