#include "image/convert.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <vector>

namespace optique::image {

ByteImage encode_srgb(const FloatImage& linear) {
  ByteImage encoded(linear.width, linear.height, 4);
  const int channels = linear.channels;
  auto encode = [](float value) {
    const double c = std::clamp(static_cast<double>(value), 0.0, 1.0);
    const double e = c < 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(e * 255.0));
  };
  for (int y = 0; y < linear.height; ++y) {
    for (int x = 0; x < linear.width; ++x) {
      for (int c = 0; c < 3; ++c) encoded.at(x, y, c) = encode(linear.at(x, y, channels >= 3 ? c : 0));
      encoded.at(x, y, 3) = 255;
    }
  }
  return encoded;
}

FloatImage box_downsample(const FloatImage& image, int factor) {
  assert(factor >= 1 && image.width % factor == 0 && image.height % factor == 0);
  if (factor == 1) return image;
  FloatImage out(image.width / factor, image.height / factor, image.channels);
  const double scale = 1.0 / (static_cast<double>(factor) * factor);
  std::vector<double> sum(static_cast<std::size_t>(out.width) * out.channels);
  for (int y = 0; y < out.height; ++y) {
    std::fill(sum.begin(), sum.end(), 0.0);
    for (int dy = 0; dy < factor; ++dy) {
      const float* src = image.pixels.data() + static_cast<std::size_t>(y * factor + dy) * image.width * image.channels;
      for (int x = 0; x < image.width; ++x) {
        for (int c = 0; c < image.channels; ++c) {
          sum[static_cast<std::size_t>(x / factor) * out.channels + c] += src[x * image.channels + c];
        }
      }
    }
    for (std::size_t i = 0; i < sum.size(); ++i) {
      out.pixels[static_cast<std::size_t>(y) * out.width * out.channels + i] = static_cast<float>(sum[i] * scale);
    }
  }
  return out;
}

}  // namespace optique::image
