// What relates one section of the installation to another, in one place.
#include <cmath>

#include "config/sections.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

// A defocus projector shows only the blurred share of the image: without a focus
// partner on the same screen for the same eye, the sharp share is missing, and
// the other way round.
void stacked_pairs(const Installation& built, Checker& check) {
  for (std::size_t i = 0; i < built.projectors.size(); ++i) {
    const Projector& p = built.projectors[i];
    const ContentRole role = p.content.role;
    if ((role != ContentRole::focus && role != ContentRole::defocus) || p.screen >= built.screens.size()) continue;
    const ContentRole wanted = role == ContentRole::focus ? ContentRole::defocus : ContentRole::focus;
    const bool partnered = std::any_of(built.projectors.begin(), built.projectors.end(), [&](const Projector& other) {
      return other.content.role == wanted && other.screen == p.screen && other.eye == p.eye;
    });
    if (!partnered) {
      check.fail(projector_path(i) + ".content.role", "a '" + std::string(to_string(role)) + "' projector needs a '" +
                                                          std::string(to_string(wanted)) + "' partner on screen '" +
                                                          built.screen_of(p).id + "' for the same eye, and '" + p.id +
                                                          "' has none: the pair shows depth of field together");
    }
  }
}

// A preset's field times are shares of its projector's frame: at another frame
// rate every field would last longer or shorter than the projector's.
void preset_frame_rate(const schema::Projector& p, const Projector& built, std::size_t i, double rate, Checker& check) {
  if (!p.has_color_fields() || p.color_fields().preset().empty() || built.color_fields.method == FieldMethod::off) {
    return;
  }
  const auto preset_rate = config::preset_frame_rate(p.color_fields().preset());
  if (!preset_rate || std::abs(*preset_rate - rate) <= 0.01) return;
  check.fail(projector_path(i) + ".color_fields.preset",
             "'" + p.color_fields().preset() + "' is the field timing of a " + number_text(*preset_rate) +
                 " Hz projector, but master.frame_rate is " + number_text(rate) + " Hz: each field would last " +
                 number_text(*preset_rate / rate) + " times as long (set master.frame_rate, or give the fields)");
}

// Interpolation draws key frames from the scene sent ahead; a live tracked
// head cannot be sent ahead, only predicted that far.
void interpolation_and_live_head(const Projector& p, std::size_t i, const Viewer& viewer, Checker& check) {
  if (!p.up_conversion.enabled() || p.up_conversion.mode != UpMode::interpolate || !viewer.tracking ||
      viewer.tracking->source == TrackingSource::replay) {
    return;
  }
  check.fail(projector_path(i) + ".up_conversion.mode",
             "interpolate draws key frames from the scene ratio − 1 frames ahead, but the head is tracked live "
             "(viewer.tracking): it cannot be known ahead; use extrapolate");
}

}  // namespace

void check_across_sections(const schema::Installation& installation, const Installation& built, Scope scope,
                           Checker& check) {
  const double rate = built.master.frame_rate > 0.0 && std::isfinite(built.master.frame_rate) ? built.master.frame_rate
                                                                                              : defaults::kFrameRate;
  for (std::size_t i = 0; i < built.projectors.size(); ++i) {
    preset_frame_rate(installation.projectors(static_cast<int>(i)), built.projectors[i], i, rate, check);
    interpolation_and_live_head(built.projectors[i], i, built.viewer, check);
  }
  if (scope == Scope::installation) {
    stacked_pairs(built, check);
    if (installation.has_depth_of_field() && !needs_depth_of_field(built.projectors)) {
      check.fail("depth_of_field", "set, but no projector has role 'focus' or 'defocus'");
    }
  }
}

}  // namespace optique::config
