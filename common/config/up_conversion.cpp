#include "config/up_conversion.h"

#include <fmt/format.h>

namespace optique::config {

std::string_view to_string(UpMethod method) { return method == UpMethod::motion ? "motion" : "average"; }

std::string_view to_string(UpMode mode) { return mode == UpMode::extrapolate ? "extrapolate" : "interpolate"; }

std::string describe(const UpConversion& up) {
  if (!up.enabled()) return "";
  std::string text = fmt::format("a key frame every {} frames, the frames between by {} ({}{})", up.ratio,
                                 to_string(up.method), to_string(up.mode), up.spread ? ", key frames spread" : "");
  if (up.adaptive()) text += fmt::format("; the ratio adapts to keep {:.1f} dB PSNR_Y", up.min_psnr);
  return text;
}

UpConversion parse_up_conversion(const schema::UpConversion& up, const std::string& path,
                                 std::vector<Problem>& problems) {
  UpConversion out;
  if (up.ratio() > static_cast<std::uint32_t>(kMaxUpRatio)) {
    problems.push_back({path + ".ratio", "must be 2…" + std::to_string(kMaxUpRatio) +
                                             " display frames per key frame, or 0 or 1 for every frame rendered (got " +
                                             std::to_string(up.ratio()) + ")"});
  } else {
    out.ratio = up.ratio() <= 1 ? 1 : static_cast<int>(up.ratio());
  }
  if (up.method().empty() || up.method() == "motion") {
    out.method = UpMethod::motion;
  } else if (up.method() == "average") {
    out.method = UpMethod::average;
  } else {
    problems.push_back({path + ".method", "must be motion or average (got '" + up.method() + "')"});
  }
  bool mode_known = true;
  if (up.mode().empty() || up.mode() == "extrapolate") {
    out.mode = UpMode::extrapolate;
  } else if (up.mode() == "interpolate") {
    out.mode = UpMode::interpolate;
  } else {
    mode_known = false;
    problems.push_back({path + ".mode", "must be extrapolate or interpolate (got '" + up.mode() + "')"});
  }
  if (up.has_min_psnr()) {
    const double floor = up.min_psnr();
    if (floor == 0.0 || (floor >= 10.0 && floor <= 100.0)) {
      out.min_psnr = floor;
    } else {
      problems.push_back({path + ".min_psnr",
                          "must be 10…100 dB of PSNR_Y, or 0 for a fixed ratio (got " + std::to_string(floor) + ")"});
    }
  }
  if (up.has_min_psnr() && up.min_psnr() > 0.0 && out.method == UpMethod::average) {
    problems.push_back({path + ".min_psnr",
                        "the adaptive ratio weighs frames that motion builds; method average (the paper's baseline) "
                        "keeps its ratio fixed and would ignore it: leave min_psnr out"});
  }
  out.spread = up.spread();
  if (mode_known && out.method == UpMethod::average && out.mode == UpMode::extrapolate) {
    problems.push_back({path + ".method", "average blends the key frames before and after: it needs mode interpolate"});
  }
  return out;
}

std::optional<Problem> up_conversion_with_fields(const UpConversion& up, const ColorFields& fields) {
  if (!up.enabled() || !fields.sequential()) return std::nullopt;
  if (fields.method != FieldMethod::up_conversion) {
    return Problem{"color_fields.method",
                   "must be \"up-conversion\" with up_conversion (got \"" + std::string(to_string(fields.method)) +
                       "\"): the fields of a frame built between key frames are built from them too, at their own "
                       "moments; \"" +
                       std::string(to_string(fields.method)) + "\" would render every frame anyway"};
  }
  return std::nullopt;
}

}  // namespace optique::config
