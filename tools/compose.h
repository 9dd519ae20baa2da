#pragma once
// `optique-master compose`: what each screen received at one frame, from the
// nodes' captures (optics simulator, common/optics/compose.h). Projectors are
// grouped by screen and eye; each group gives one composite:
//   OUT/screens/<screen-id>/frame-NNNNNN.{exr,png}        mono projectors
//   OUT/screens/<screen-id>.left/…, <screen-id>.right/…   stereo eyes
// The EXR is linear light, the PNG sRGB-encoded; both at the screen's pixels per
// metre, the size of render-reference's images.

#include <cstdint>
#include <string>
#include <vector>

#include <spdlog/logger.h>

#include "config/load.h"
#include "util/result.h"

namespace optique::tools {

struct ComposedScreen {
  std::string folder;  // <screen-id>, or <screen-id>.left / .right
  std::string screen;  // screen id
  config::Eye eye = config::Eye::mono;
  std::vector<std::string> projectors;  // the captures that went into it
  int width = 0;                        // pixels
  int height = 0;
  int subsamples = 0;    // per output pixel and axis, the largest used
  double covered = 0.0;  // share of the screen's pixels (centres) that some projector lights
  std::string exr_path;
  std::string png_path;
};

struct ComposeSummary {
  std::uint64_t frame = 0;
  std::vector<ComposedScreen> screens;
};

// Reads CAPTURES/<projector-id>/frame-NNNNNN.png (the signal) for every projector (as the
// nodes write them under OUT/nodes), composes each screen × eye group and writes
// OUT_DIR/screens/<folder>/frame-NNNNNN.{exr,png}. Logs one line per composite.
// Fails, naming the file, when a capture is missing (was the frame captured? run
// with --capture-every), unreadable, or not the projector's size.
[[nodiscard]] Result<ComposeSummary> compose_frame(const config::LoadedConfig& config, std::uint64_t frame,
                                                   const std::string& captures_dir, const std::string& out_dir,
                                                   spdlog::logger& log);

}  // namespace optique::tools
