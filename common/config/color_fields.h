#pragma once
// A projector's colour fields, checked and typed: a single-chip DLP projector
// shows red, green and blue one after another, each for part of the frame, and
// each field is drawn for the moment it is on screen (Lancelle, Voß & Fellner,
// "Fast Motion Rendering for Single-Chip Stereo DLP Projectors").
// Times are in frame periods from the frame's display time.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::config {

enum class Channel { red, green, blue };
// per_field: one render per field; gather: one render with screen-space
// velocity and depth, each field gathered from it along the motion;
// up_conversion: one render, each other field built from it at its moment as
// frame-rate up-conversion builds a frame between key frames (an exact per-
// pixel motion field; what the render did not see shaded anew); off: every
// colour at the display time.
enum class FieldMethod { per_field, gather, up_conversion, off };

[[nodiscard]] std::string_view to_string(Channel channel);
[[nodiscard]] std::string_view to_string(FieldMethod method);

struct ColorField {
  Channel channel = Channel::red;
  int image = 0;          // which of the frame's images (a stereo projector used as mono shows two)
  double offset = 0.0;    // the centre of its window, frame periods from the display time
  double duration = 0.0;  // frame periods

  [[nodiscard]] double start() const { return offset - 0.5 * duration; }
  [[nodiscard]] double end() const { return offset + 0.5 * duration; }
  friend bool operator==(const ColorField&, const ColorField&) = default;
};

inline constexpr int kDefaultGatherSamples = 8;
inline constexpr int kMinGatherSamples = 2;
inline constexpr int kMaxGatherSamples = 32;

struct ColorFields {
  std::vector<ColorField> fields;  // in the order given; empty: all colours at once
  int images = 1;                  // images per frame: 1, or 2 for a stereo projector used as mono
  FieldMethod method = FieldMethod::per_field;
  double velocity_threshold = 0.0;             // drawn image's pixels per frame period; 0: none
  int gather_samples = kDefaultGatherSamples;  // per field and pixel, along the motion

  // Whether the projector draws its fields at their own times.
  [[nodiscard]] bool sequential() const { return !fields.empty() && method != FieldMethod::off; }
  // Whether they are gathered from one render (the velocity target and tiles).
  [[nodiscard]] bool gathers() const { return sequential() && method == FieldMethod::gather; }
  // Whether they are built from one render by up-conversion (its key slots and passes).
  [[nodiscard]] bool up_converts() const { return sequential() && method == FieldMethod::up_conversion; }
  // Whether what is faster than the threshold gets motion blur (either method).
  [[nodiscard]] bool blurs() const { return sequential() && velocity_threshold > 0.0; }
  // Whether it needs each pixel's velocity: to gather, or to blur.
  [[nodiscard]] bool needs_velocity() const { return gathers() || blurs(); }
  // The share of a frame `channel` is on: its fields' durations, over all the
  // frame's images.
  [[nodiscard]] double on_share(Channel channel) const;
  friend bool operator==(const ColorFields&, const ColorFields&) = default;
};

// What the fields are, for a node's log ("6 colour fields per frame, gathered
// from one render, blurred above 2.0 px per frame"); empty when the projector
// shows all colours at once.
[[nodiscard]] std::string describe(const ColorFields& fields);

// The presets' names, for messages and docs.
[[nodiscard]] const std::vector<std::string>& color_field_presets();
// The frame rate preset `name`'s field times are for (its offsets and
// durations are shares of that frame); none for an unknown name.
[[nodiscard]] std::optional<double> preset_frame_rate(const std::string& name);

// Checks `fields` (a projector's `color_fields`, at `path` in the file) and types
// it, the preset expanded. Every problem goes to `problems`, each with its own
// message: an unknown preset or name, a preset and fields together, a channel
// twice in one image or missing from it, a window outside the frame
// [−½, ½], durations that add to more than a frame, fields that overlap.
[[nodiscard]] ColorFields parse_color_fields(const schema::ColorFields& fields, const std::string& path,
                                             std::vector<Problem>& problems);

}  // namespace optique::config
