#pragma once
// Image files through OpenImageIO: linear EXR (half float) and encoded PNG.

#include <string>

#include "image/image.h"
#include "util/result.h"

namespace optique::image {

[[nodiscard]] Result<void> write_exr(const std::string& path, const FloatImage& image);
[[nodiscard]] Result<void> write_png(const std::string& path, const ByteImage& image);
[[nodiscard]] Result<void> write_png(const std::string& path, const WordImage& image);  // 16 bits per channel
// Any format OpenImageIO reads, as float (8-bit files scaled to [0, 1], no decoding).
[[nodiscard]] Result<FloatImage> read_image(const std::string& path);

}  // namespace optique::image
