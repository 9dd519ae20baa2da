#include "image/frame_files.h"

#include <cstdio>
#include <filesystem>

#include "image/image_io.h"

namespace optique::image {

std::string frame_path(const std::string& folder, std::uint64_t frame, const std::string& extension) {
  char name[64];
  std::snprintf(name, sizeof name, "frame-%06llu.%s", static_cast<unsigned long long>(frame), extension.c_str());
  return (std::filesystem::path(folder) / name).string();
}

namespace {

template <class Encoded>
Result<void> write_both(const std::string& folder, std::uint64_t frame, const FloatImage& linear,
                        const Encoded& encoded) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return Error{"cannot create " + folder + ": " + ec.message()};
  if (auto written = write_exr(frame_path(folder, frame, "exr"), linear); !written) return written;
  return write_png(frame_path(folder, frame, "png"), encoded);
}

}  // namespace

Result<void> write_frame(const std::string& folder, std::uint64_t frame, const FloatImage& linear,
                         const ByteImage& encoded) {
  return write_both(folder, frame, linear, encoded);
}

Result<void> write_frame(const std::string& folder, std::uint64_t frame, const FloatImage& linear,
                         const WordImage& encoded) {
  return write_both(folder, frame, linear, encoded);
}

}  // namespace optique::image
