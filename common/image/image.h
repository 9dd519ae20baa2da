#pragma once
// Images in memory: row-major, top row first, interleaved channels. Float images
// hold linear light; 8-bit images hold what goes to a projector (encoded).

#include <cstdint>
#include <vector>

namespace optique::image {

template <class T>
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<T> pixels;

  Image() = default;
  Image(int w, int h, int c) : width(w), height(h), channels(c), pixels(static_cast<std::size_t>(w) * h * c) {}

  [[nodiscard]] T& at(int x, int y, int c) { return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c]; }
  [[nodiscard]] const T& at(int x, int y, int c) const {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
  [[nodiscard]] bool empty() const { return pixels.empty(); }
};

using FloatImage = Image<float>;
using ByteImage = Image<std::uint8_t>;
using WordImage = Image<std::uint16_t>;  // a signal deeper than 8 bits

// Reverses the row order (OpenGL reads bottom row first).
template <class T>
void flip_rows(Image<T>& image) {
  const std::size_t row = static_cast<std::size_t>(image.width) * image.channels;
  for (int y = 0; y < image.height / 2; ++y) {
    auto* a = image.pixels.data() + static_cast<std::size_t>(y) * row;
    auto* b = image.pixels.data() + static_cast<std::size_t>(image.height - 1 - y) * row;
    for (std::size_t i = 0; i < row; ++i) std::swap(a[i], b[i]);
  }
}

}  // namespace optique::image
