#pragma once
// Where frame images go: FOLDER/frame-NNNNNN.exr (linear) and .png (encoded), for
// node captures, reference renders and screen composites alike.

#include <cstdint>
#include <string>

#include "image/image.h"
#include "util/result.h"

namespace optique::image {

[[nodiscard]] std::string frame_path(const std::string& folder, std::uint64_t frame, const std::string& extension);

// Creates `folder` if needed and writes both files.
[[nodiscard]] Result<void> write_frame(const std::string& folder, std::uint64_t frame, const FloatImage& linear,
                                       const ByteImage& encoded);
// The same with a 16-bit PNG, for signals deeper than 8 bits.
[[nodiscard]] Result<void> write_frame(const std::string& folder, std::uint64_t frame, const FloatImage& linear,
                                       const WordImage& encoded);

}  // namespace optique::image
