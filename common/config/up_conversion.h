#pragma once
// A projector's frame-rate up-conversion, checked and typed: its node renders a
// key frame every `ratio` display frames and builds the frames between from the
// key frames and the exact screen motion of the visible surfaces (the up-
// conversion paper's motion-compensated method), or, as the baseline, their
// average.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/color_fields.h"
#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::config {

// motion: each pixel taken from where its surface was in a key frame; average:
// the key frames before and after, half each (the paper's baseline).
enum class UpMethod { motion, average };
// extrapolate: from the last key frame only (no latency); interpolate: between
// the key frames before and after (ratio − 1 frames later).
enum class UpMode { extrapolate, interpolate };

[[nodiscard]] std::string_view to_string(UpMethod method);
[[nodiscard]] std::string_view to_string(UpMode mode);

inline constexpr int kMaxUpRatio = 16;
// The farthest ahead of its frame the master sends a scene: interpolation with
// the key frames spread (UpConversion::frames_ahead).
inline constexpr int kMostFramesAhead = 2 * kMaxUpRatio - 1;
// What the frames between must keep at least, by default: the up-conversion
// paper's "visually equal" (dB of PSNR_Y).
inline constexpr double kDefaultMinPsnr = 30.0;

struct UpConversion {
  int ratio = 1;  // display frames per key frame; 1: every frame rendered
  UpMethod method = UpMethod::motion;
  UpMode mode = UpMode::extrapolate;
  // The adaptive ratio's floor, dB of PSNR_Y; 0: the ratio is fixed. The
  // average (a baseline to compare with) keeps its ratio.
  double min_psnr = kDefaultMinPsnr;
  [[nodiscard]] bool adaptive() const { return min_psnr > 0.0 && method == UpMethod::motion; }
  // Each key frame drawn in bands over the frames before it is used, not at once.
  bool spread = false;
  // How many frames ahead of its frame the master sends the scene of a later
  // key frame: interpolation needs the next key frame before the frames before
  // it, and with spread key frames the one after (0: nothing sent ahead).
  [[nodiscard]] int frames_ahead() const {
    if (!enabled() || mode != UpMode::interpolate) return 0;
    return spread ? 2 * ratio - 1 : ratio - 1;
  }

  [[nodiscard]] bool enabled() const { return ratio > 1; }
  friend bool operator==(const UpConversion&, const UpConversion&) = default;
};

// What the node draws, for its log ("a key frame every 4 frames, the frames
// between by motion (extrapolate); the ratio adapts to keep 30.0 dB PSNR_Y");
// empty when every frame is rendered.
[[nodiscard]] std::string describe(const UpConversion& up);

// Checks `up` (a projector's `up_conversion`, at `path` in the file) and types
// it. Every problem goes to `problems`, each with its own message: a ratio
// beyond kMaxUpRatio, an unknown method or mode, the average extrapolated (it
// needs the key frame after), a floor that is not 0 or 10…100 dB.
[[nodiscard]] UpConversion parse_up_conversion(const schema::UpConversion& up, const std::string& path,
                                               std::vector<Problem>& problems);

// What keeps one projector from both up-converting its frames and showing
// these colour fields (the path from the projector), or nothing. Each field of
// a frame built between key frames is built from them at its own moment, so the
// fields' method must be up-conversion (per-field or a gather would render
// every frame anyway), in one image a frame or two.
[[nodiscard]] std::optional<Problem> up_conversion_with_fields(const UpConversion& up, const ColorFields& fields);

}  // namespace optique::config
