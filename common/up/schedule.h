#pragma once
// Which display frames a projector that up-converts draws in full (key frames)
// and how it builds the others (config/up_conversion.h): decisions from frame
// numbers, scene states and what the last check measured. No GL: the pipeline
// carries the plans out.
//
// extrapolate: a key frame every `ratio` frames; the frames after it are built
// from it alone. interpolate: the key frame `ratio` frames ahead is drawn from
// the state the master sent ahead, as soon as the last one is shown, and the
// frames between come from both. Either way a key frame is drawn at once,
// whatever the ratio, where a kept one would mix two sides of a cut: a light
// switched on or off, the viewer's eye moved farther than kCutEyeJump, or the
// navigation moved as far, turned more than 10° or scaled.
//
// spread: each key frame is drawn a band of rows a frame over the frames before
// it is needed, so that no frame pays for a whole key frame. extrapolate: the
// key frame of a frame is drawn over that frame and the next ratio − 1, and
// used from then on (the frames between come from a key frame ratio … 2·ratio
// − 1 frames old); interpolate: the key frame after the next, from the scene
// sent 2·ratio − 1 frames ahead, is drawn over the frames up to the one that
// shows the next. Where frames were skipped, the frame a key frame is due with
// draws all the bands it lacks. A cut, too little sent ahead, or the adaptive
// ratio at 1 still draws a key frame at once.
//
// Adaptive ratio: before each key frame that comes `ratio` frames after the
// last is kept, the frame that key frame would have built at its moment is
// checked against it (PSNR_Y as displayed): below the floor, the key frames
// come a frame sooner; kRaiseMargin above it, a frame later, up to `ratio`. The
// check extrapolates over the whole interval, so with interpolation (whose
// frames are at most half an interval from a key frame) it is cautious; with
// spread extrapolation (whose frames are one to two intervals from theirs) it
// weighs the youngest frames, and is optimistic.

#include <cstdint>
#include <functional>
#include <optional>
#include <string_view>

#include "config/up_conversion.h"
#include "scene/state.h"
#include "up/between.h"

namespace optique::up {

// Farther than this (metres) between a key frame's eye and a frame's, the key
// frame shows another view: a cut, not motion.
inline constexpr double kCutEyeJump = 0.5;
// A navigation turned by more than 10° (the quaternions' dot product: the
// cosine of half the angle).
inline constexpr double kCutTurnCosine = 0.99619469809174555;  // cos(5°)
// dB above the floor before the key frames come further apart again.
inline constexpr double kRaiseMargin = 3.0;

// What a display frame was: drawn in full (no up-conversion), a key frame
// drawn now, one built between key frames, or a key frame drawn ahead and shown
// now.
enum class FrameKind { full, key, between, shown };
[[nodiscard]] std::string_view to_string(FrameKind kind);

// What to draw for one display frame.
struct UpPlan {
  // Draw a state in full and keep it as key `key_slot`: this frame's own (then
  // it is shown), or, ahead of time, that of frame `ahead_frame` (interpolate).
  bool draw_key = false;
  std::optional<std::uint64_t> ahead_frame;
  int key_slot = 0;
  // The state to draw it from (this frame's, or the one sent ahead), as the
  // schedule keeps it: valid until the next plan() or forget().
  const scene::SceneState* key_state = nullptr;
  // Before keeping it: how far the frame between from key `check_slot` would
  // have been from it, for the adaptive ratio (UpSchedule::checked). With
  // spread key frames, when the band that completes one is drawn.
  std::optional<int> check_slot;
  // Spread key frames: bands `index` … `index + bands − 1` of `count` (rows of
  // the image, from the bottom; one band, or all that are left where frames
  // were skipped) of the key frame of frame `frame`, drawn from `state` into key
  // slot `slot`. After the last band it is kept: frames from the next on use it.
  struct Band {
    int slot = 0;
    int index = 0;
    int count = 1;
    int bands = 1;
    std::uint64_t frame = 0;
    const scene::SceneState* state = nullptr;  // valid until the next plan() or forget()
    [[nodiscard]] bool last() const { return index + bands == count; }
  };
  std::optional<Band> band;
  // Build this frame from the kept keys (frame.first is the earlier one).
  bool between = false;
  BetweenFrame frame;
  // Show kept key `shown_slot` as it is: it was drawn ahead for this frame.
  std::optional<int> shown_slot;
  [[nodiscard]] FrameKind kind() const {
    return between ? FrameKind::between : shown_slot ? FrameKind::shown : FrameKind::key;
  }
  // Why a key frame is drawn now ("first frame", "ratio", "lights switched",
  // "viewer jumped", "nothing ahead"), for the log.
  std::string_view why;
};

class UpSchedule {
 public:
  explicit UpSchedule(const config::UpConversion& settings);

  // States the master sent ahead of their frame, by frame; nullptr where none.
  using Ahead = std::function<const scene::SceneState*(std::uint64_t frame)>;
  // The plan for display frame `frame`, which shows `state`. Frames come in
  // order; one that goes back or skips past the kept keys starts over.
  [[nodiscard]] UpPlan plan(std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead = {});
  // What the plan's check measured, dB of PSNR_Y (+infinity: identical).
  void checked(double psnr_y);
  // The kept key frames no longer show what is drawn (a key frame that could
  // not be drawn, another share of the lights): the next frame is a key frame.
  void forget();

  // The band of the plan could not be drawn (its key frame's moment cannot be
  // seen): that key frame is dropped, the next is begun on a later frame.
  void drop_band();

  // Display frames per key frame now (the adaptive ratio's; `ratio` when fixed).
  [[nodiscard]] int ratio() const { return ratio_; }
  // Key slots the plans use: three with spread key frames, otherwise two.
  [[nodiscard]] int slots() const { return slots_for(settings_); }
  [[nodiscard]] static int slots_for(const config::UpConversion& settings) { return settings.spread ? kKeySlots : 2; }
  [[nodiscard]] const config::UpConversion& settings() const { return settings_; }

 private:
  struct Key {
    std::uint64_t frame = 0;
    int slot = 0;
    scene::SceneState state;
  };
  struct Building {
    Key key;
    int next = 0;  // the band drawn next
    int count = 1;
    std::uint64_t due = 0;  // the frame its last band is drawn with at the latest
  };
  [[nodiscard]] UpPlan key_now(std::uint64_t frame, const scene::SceneState& state, std::string_view why);
  [[nodiscard]] UpPlan extrapolated(std::uint64_t frame, const scene::SceneState& state);
  [[nodiscard]] UpPlan interpolated(std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead);
  // Spread: the next band of the key frame being drawn, begun here if none is.
  void add_band(UpPlan& plan, std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead);
  [[nodiscard]] int free_slot() const;

  config::UpConversion settings_;
  int ratio_ = 1;
  std::optional<Key> first_;          // the key frame shown last (extrapolate: the only one)
  std::optional<Key> second_;         // interpolate: the one drawn ahead
  std::optional<Building> building_;  // spread: the key frame drawn a band a frame
};

// Whether a frame showing `state` may be built from a key frame of `key`: no
// light switched, the eye not moved as far as a cut. `why` says what differs.
[[nodiscard]] bool same_side(const scene::SceneState& key, const scene::SceneState& state,
                             std::string_view* why = nullptr);

}  // namespace optique::up
