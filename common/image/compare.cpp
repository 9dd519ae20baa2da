#include "image/compare.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>

namespace optique::image {
namespace {

double psnr(double squared_error_sum, std::size_t count, double peak) {
  if (squared_error_sum == 0.0) return std::numeric_limits<double>::infinity();
  const double mse = squared_error_sum / static_cast<double>(count);
  return 10.0 * std::log10(peak * peak / mse);
}

}  // namespace

Result<BlockClasses> block_classes(const FloatImage& a, const FloatImage& b, int block, double peak) {
  if (a.width != b.width || a.height != b.height || a.channels < 3 || b.channels < 3 || a.width == 0 || a.height == 0 ||
      block < 1) {
    return Error{"block classes need two non-empty RGB images of one size and a block of at least 1 pixel"};
  }
  BlockClasses out;
  out.worst_db = std::numeric_limits<double>::infinity();
  std::size_t blocks = 0;
  constexpr double kWeights[3] = {0.299, 0.587, 0.114};
  constexpr double kIdentical = 100.0;
  for (int by = 0; by < a.height; by += block) {
    for (int bx = 0; bx < a.width; bx += block) {
      double sum[3] = {0.0, 0.0, 0.0};
      std::size_t count = 0;
      for (int y = by; y < std::min(by + block, a.height); ++y) {
        for (int x = bx; x < std::min(bx + block, a.width); ++x) {
          for (int c = 0; c < 3; ++c) {
            const double d = static_cast<double>(a.at(x, y, c)) - b.at(x, y, c);
            sum[c] += d * d;
          }
          ++count;
        }
      }
      double db = 0.0;
      for (int c = 0; c < 3; ++c) db += kWeights[c] * std::min(kIdentical, psnr(sum[c], count, peak));
      int k = 0;
      while (k < 3 && db >= BlockClasses::kBounds[k]) ++k;
      out.share[k] += 1.0;
      out.worst_db = std::min(out.worst_db, db);
      ++blocks;
    }
  }
  for (double& share : out.share) share /= static_cast<double>(blocks);
  return out;
}

Result<Comparison> compare(const FloatImage& a, const FloatImage& b, double peak) {
  if (a.width != b.width || a.height != b.height) {
    return Error{"image sizes differ: " + std::to_string(a.width) + "×" + std::to_string(a.height) + " and " +
                 std::to_string(b.width) + "×" + std::to_string(b.height)};
  }
  if (a.channels < 3 || b.channels < 3) return Error{"both images need at least 3 channels (RGB)"};
  if (a.width == 0 || a.height == 0) return Error{"the images are empty"};
  double sum[3] = {0.0, 0.0, 0.0};
  double luma_sum = 0.0;
  double max_error = 0.0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      double luma_a = 0.0;
      double luma_b = 0.0;
      for (int c = 0; c < 3; ++c) {
        const double va = a.at(x, y, c);
        const double vb = b.at(x, y, c);
        const double d = va - vb;
        sum[c] += d * d;
        max_error = std::max(max_error, std::abs(d));
        constexpr double kLuma[3] = {0.299, 0.587, 0.114};
        luma_a += kLuma[c] * va;
        luma_b += kLuma[c] * vb;
      }
      luma_sum += (luma_a - luma_b) * (luma_a - luma_b);
    }
  }
  const std::size_t count = static_cast<std::size_t>(a.width) * a.height;
  Comparison result;
  result.psnr_r = psnr(sum[0], count, peak);
  result.psnr_g = psnr(sum[1], count, peak);
  result.psnr_b = psnr(sum[2], count, peak);
  result.psnr_luma = psnr(luma_sum, count, peak);
  result.psnr_y_weighted = 0.299 * result.psnr_r + 0.587 * result.psnr_g + 0.114 * result.psnr_b;
  result.max_abs_error = max_error;
  return result;
}

FloatImage difference(const FloatImage& a, const FloatImage& b, float gain) {
  assert(a.width == b.width && a.height == b.height && a.channels >= 3 && b.channels >= 3);
  FloatImage out(a.width, a.height, 4);
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = gain * std::abs(a.at(x, y, c) - b.at(x, y, c));
      out.at(x, y, 3) = 1.0f;
    }
  }
  return out;
}

FloatImage crop(const FloatImage& source, int x, int y, int width, int height) {
  assert(x >= 0 && y >= 0 && width >= 0 && height >= 0 && x + width <= source.width && y + height <= source.height);
  FloatImage part(width, height, source.channels);
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      for (int c = 0; c < source.channels; ++c) part.at(col, row, c) = source.at(x + col, y + row, c);
    }
  }
  return part;
}

void paste(FloatImage& target, const FloatImage& source, int x, int y) {
  assert(target.channels == source.channels);
  for (int row = 0; row < source.height; ++row) {
    const int ty = y + row;
    if (ty < 0 || ty >= target.height) continue;
    for (int col = 0; col < source.width; ++col) {
      const int tx = x + col;
      if (tx < 0 || tx >= target.width) continue;
      for (int c = 0; c < source.channels; ++c) target.at(tx, ty, c) = source.at(col, row, c);
    }
  }
}

double luma(const FloatImage& image, int x, int y) {
  return 0.299 * image.at(x, y, 0) + 0.587 * image.at(x, y, 1) + 0.114 * image.at(x, y, 2);
}

double psnr_luma_where(const FloatImage& a, const FloatImage& b, const std::function<bool(int x, int y)>& where,
                       double peak) {
  double squared = 0.0;
  std::size_t count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (!where(x, y)) continue;
      const double d = luma(a, x, y) - luma(b, x, y);
      squared += d * d;
      ++count;
    }
  }
  if (count == 0 || squared == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(peak * peak * static_cast<double>(count) / squared);
}

}  // namespace optique::image
