#include "config/color_fields.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "util/join.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

// Windows that touch at a shared edge do not overlap; rounding in a file's
// decimals (1/6 written as 0.1666667) must not make them.
constexpr double kSlack = 1e-6;

struct Preset {
  std::string name;
  int images = 1;
  std::vector<ColorField> fields;
  double frame_rate = 60.0;  // what its shares of a frame are of
};

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = [] {
    // Lancelle et al. read a 120 Hz projector's offsets off a photo taken while
    // turning the camera: B −0.2, R 0.0, G +0.32 of the frame. They give no
    // durations; 0.2 each keeps the three windows apart.
    Preset brg{"dlp-brg-120hz", 1, {}, 120.0};
    brg.fields = {{Channel::blue, 0, -0.2, 0.2}, {Channel::red, 0, 0.0, 0.2}, {Channel::green, 0, 0.32, 0.2}};
    // A 2×60 Hz stereo projector used as mono 120 Hz: per 60 Hz frame, B R G of
    // the left image, then of the right, at ∓5/6, ∓3/6, ∓1/6 of 1/120 s, each a
    // sixth of the frame.
    Preset stereo{"dlp-stereo-as-mono", 2, {}, 60.0};
    const std::array<Channel, 3> order{Channel::blue, Channel::red, Channel::green};
    for (int i = 0; i < 6; ++i) {
      stereo.fields.push_back({order[static_cast<std::size_t>(i % 3)], i / 3, (2 * i - 5) / 12.0, 1.0 / 6.0});
    }
    return std::vector<Preset>{brg, stereo};
  }();
  return all;
}

std::optional<Channel> channel_named(const std::string& name) {
  if (name == "red") return Channel::red;
  if (name == "green") return Channel::green;
  if (name == "blue") return Channel::blue;
  return std::nullopt;
}

// Appended piece by piece, not "[" + text + …: GCC 12 at -O3 takes the inlined
// operator+ for a copy that may overlap itself (-Werror=restrict, a false
// positive that fails the Release build).
std::string window_text(const ColorField& f) {
  std::string text = "[";
  text += number_text(f.start());
  text += ", ";
  text += number_text(f.end());
  text += ']';
  return text;
}

}  // namespace

std::string_view to_string(Channel channel) {
  switch (channel) {
    case Channel::red:
      return "red";
    case Channel::green:
      return "green";
    case Channel::blue:
      return "blue";
  }
  return "?";
}

std::string describe(const ColorFields& fields) {
  if (fields.fields.empty()) return "";
  std::string text = fmt::format("{} colour fields per frame", fields.fields.size());
  if (fields.images > 1) text += fmt::format(" over {} images", fields.images);
  switch (fields.method) {
    case FieldMethod::per_field:
      text += ", each drawn at its own time";
      break;
    case FieldMethod::gather:
      text += fmt::format(", gathered from one render ({} samples)", fields.gather_samples);
      break;
    case FieldMethod::up_conversion:
      text += ", built from one render by up-conversion";
      break;
    case FieldMethod::off:
      text += ", all drawn at the display time (method off)";
      break;
  }
  if (fields.blurs()) text += fmt::format(", blurred above {:.1f} px per frame", fields.velocity_threshold);
  return text;
}

double ColorFields::on_share(Channel channel) const {
  double share = 0.0;
  for (const ColorField& f : fields) share += f.channel == channel ? f.duration : 0.0;
  return share;
}

std::string_view to_string(FieldMethod method) {
  switch (method) {
    case FieldMethod::per_field:
      return "per-field";
    case FieldMethod::gather:
      return "gather";
    case FieldMethod::up_conversion:
      return "up-conversion";
    case FieldMethod::off:
      return "off";
  }
  return "?";
}

std::optional<double> preset_frame_rate(const std::string& name) {
  for (const Preset& p : presets()) {
    if (p.name == name) return p.frame_rate;
  }
  return std::nullopt;
}

const std::vector<std::string>& color_field_presets() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Preset& p : presets()) n.push_back(p.name);
    return n;
  }();
  return names;
}

ColorFields parse_color_fields(const schema::ColorFields& c, const std::string& path, std::vector<Problem>& problems) {
  ColorFields out;
  if (c.method() == "off") {
    out.method = FieldMethod::off;
  } else if (c.method() == "gather") {
    out.method = FieldMethod::gather;
  } else if (c.method() == "up-conversion") {
    out.method = FieldMethod::up_conversion;
  } else if (!c.method().empty() && c.method() != "per-field") {
    problems.push_back(
        {path + ".method", "must be per-field, gather, up-conversion or off (got '" + c.method() + "')"});
  }
  if (c.gather_samples() != 0) {
    if (c.gather_samples() < kMinGatherSamples || c.gather_samples() > kMaxGatherSamples) {
      problems.push_back({path + ".gather_samples", "must be " + std::to_string(kMinGatherSamples) + "…" +
                                                        std::to_string(kMaxGatherSamples) + ", or 0 for " +
                                                        std::to_string(kDefaultGatherSamples) + " (got " +
                                                        std::to_string(c.gather_samples()) + ")"});
    } else {
      out.gather_samples = static_cast<int>(c.gather_samples());
    }
  }
  if (!std::isfinite(c.velocity_threshold()) || c.velocity_threshold() < 0.0) {
    problems.push_back({path + ".velocity_threshold", "must be 0 (none) or more, screen pixels per frame period (got " +
                                                          number_text(c.velocity_threshold()) + ")"});
  } else if (out.method == FieldMethod::up_conversion && c.velocity_threshold() > 0.0) {
    problems.push_back({path + ".velocity_threshold",
                        "blurs what is too fast to follow with per-field or gather; up-conversion builds every "
                        "field at its moment: leave it 0 (got " +
                            number_text(c.velocity_threshold()) + ")"});
  } else {
    out.velocity_threshold = c.velocity_threshold();
  }

  const std::size_t problems_before = problems.size();  // the fields' own, from here
  // Where each field came from, for messages: the file's own, or the preset's.
  std::vector<std::string> where;
  if (!c.preset().empty()) {
    if (c.fields_size() > 0) {
      problems.push_back({path, "give either preset or fields, not both"});
      return out;
    }
    const auto preset =
        std::find_if(presets().begin(), presets().end(), [&](const Preset& p) { return p.name == c.preset(); });
    if (preset == presets().end()) {
      problems.push_back({path + ".preset", "unknown preset '" + c.preset() +
                                                "' (presets are: " + util::joined(color_field_presets()) + ")"});
      return out;
    }
    out.fields = preset->fields;
    out.images = preset->images;
    for (std::size_t i = 0; i < out.fields.size(); ++i) where.push_back(path + ".preset");
  } else {
    if (c.fields_size() == 0) {
      problems.push_back({path, "give a preset or the fields (channel, offset, duration of each)"});
      return out;
    }
    for (int i = 0; i < c.fields_size(); ++i) {
      const schema::ColorField& f = c.fields(i);
      const std::string at = path + ".fields[" + std::to_string(i) + "]";
      ColorField field;
      const auto channel = channel_named(f.channel());
      if (!channel) problems.push_back({at + ".channel", "must be red, green or blue (got '" + f.channel() + "')"});
      field.channel = channel.value_or(Channel::red);
      if (f.image() > 1) {
        problems.push_back({at + ".image", "must be 0, or 1 for a stereo projector used as mono (got " +
                                               std::to_string(f.image()) + ")"});
      }
      field.image = f.image() > 1 ? 0 : static_cast<int>(f.image());
      const bool finite = std::isfinite(f.offset()) && std::isfinite(f.duration());
      if (!std::isfinite(f.offset())) problems.push_back({at + ".offset", "must be a finite number"});
      if (!std::isfinite(f.duration()) || f.duration() <= 0.0) {
        problems.push_back({at + ".duration", "must be > 0, frame periods (got " + number_text(f.duration()) + ")"});
      }
      field.offset = f.offset();
      field.duration = f.duration();
      if (finite && f.duration() > 0.0 && (field.start() < -0.5 - kSlack || field.end() > 0.5 + kSlack)) {
        problems.push_back({at + ".offset", "its window " + window_text(field) +
                                                " leaves the frame: offset ± duration/2 must lie within [-0.5, 0.5] "
                                                "frame periods of the display time"});
      }
      if (!channel || f.image() > 1) continue;
      out.fields.push_back(field);  // checked for its channel below, even when its times are wrong
      where.push_back(at);
    }
    for (const ColorField& f : out.fields) out.images = std::max(out.images, f.image + 1);
  }
  const bool times_checked = problems.size() == problems_before;

  // Each image shows each channel once.
  for (int image = 0; image < out.images; ++image) {
    for (const Channel channel : {Channel::red, Channel::green, Channel::blue}) {
      std::vector<std::size_t> found;
      for (std::size_t i = 0; i < out.fields.size(); ++i) {
        if (out.fields[i].image == image && out.fields[i].channel == channel) found.push_back(i);
      }
      const std::string name(to_string(channel));
      if (found.empty()) {
        problems.push_back({path + ".fields", "image " + std::to_string(image) + " has no " + name +
                                                  " field: every image shows red, green and blue"});
      } else if (found.size() > 1) {
        problems.push_back({where[found[1]] + ".channel",
                            name + " twice in image " + std::to_string(image) + " (also " + where[found[0]] + ")"});
      }
    }
  }
  // One mirror array shows one field at a time (said only of windows that are
  // each right: a wrong one already has its message).
  if (!times_checked) return out;
  double total = 0.0;
  for (const ColorField& f : out.fields) total += f.duration;
  if (total > 1.0 + kSlack) {
    problems.push_back(
        {path + ".fields", "the durations add to " + number_text(total) + " frame periods: more than one frame"});
  } else {
    std::vector<std::size_t> order(out.fields.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return out.fields[a].start() < out.fields[b].start(); });
    for (std::size_t k = 1; k < order.size(); ++k) {
      const ColorField& before = out.fields[order[k - 1]];
      const ColorField& after = out.fields[order[k]];
      if (before.end() > after.start() + kSlack) {
        problems.push_back({where[order[k]] + ".offset", "its window " + window_text(after) + " overlaps " +
                                                             where[order[k - 1]] + "'s " + window_text(before) +
                                                             ": a projector shows one field at a time"});
      }
    }
  }
  return out;
}

}  // namespace optique::config
