#pragma once
// What a screen showed against what it should have: composes one captured frame
// of a run (optique-master compose), renders that frame's reference
// (optique-master render-reference) and compares them in linear light, less the
// projectors' black. For tests of stacked projectors, whose light adds.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "optique/config.pb.h"

namespace optique::testing {

struct ScreenMatch {
  double psnr_db = 0.0;  // luma, where every share fits (below)
  // Pixels whose luma differs by more than 1 % of full light: a ghost, or light missing.
  std::size_t pixels_off = 0;
};

struct ScreenCheck {
  std::string master_binary;
  std::string config;        // the installation to compose with (its projectors' captures must exist)
  std::string captures_dir;  // <projector-id>/frame-NNNNNN.png
  std::string out_dir;       // composites and the reference go here
  std::string screen;        // screen id
  // More for render-reference: {"--replay", journal} for a live scene's frame.
  std::vector<std::string> reference_args = {};
};

// Compares where the reference is at most 0.6 of full light in every channel
// (highlights brighter than one share can emit clip in a projector; the
// reference has no projectors) and two pixels in from the edges. Failures to
// compose or render are test failures (EXPECT), and give a zero match.
[[nodiscard]] ScreenMatch compare_with_reference(const ScreenCheck& check, std::uint64_t frame);

// Loads `config`, changes it, and writes it to `path` as JSON; returns `path`.
[[nodiscard]] std::string write_config_variant(const std::string& config,
                                               const std::function<void(schema::Installation&)>& change,
                                               const std::string& path);

}  // namespace optique::testing
