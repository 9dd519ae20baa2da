#include "up/schedule.h"

#include <algorithm>

#include <glm/geometric.hpp>

namespace optique::up {

std::string_view to_string(FrameKind kind) {
  switch (kind) {
    case FrameKind::full:
      return "full";
    case FrameKind::key:
      return "key";
    case FrameKind::between:
      return "between";
    case FrameKind::shown:
      return "shown";
  }
  return "?";
}

bool same_side(const scene::SceneState& key, const scene::SceneState& state, std::string_view* why) {
  if (key.lights_off != state.lights_off) {
    if (why) *why = "lights switched";
    return false;
  }
  if (glm::distance(key.eye_now, state.eye_now) > kCutEyeJump) {
    if (why) *why = "viewer jumped";
    return false;
  }
  return true;
}

UpSchedule::UpSchedule(const config::UpConversion& settings) : settings_(settings), ratio_(settings.ratio) {}

void UpSchedule::forget() {
  first_.reset();
  second_.reset();
}

void UpSchedule::checked(double psnr_y) {
  if (!settings_.adaptive()) return;
  if (psnr_y < settings_.min_psnr) {
    ratio_ = std::max(1, ratio_ - 1);
  } else if (psnr_y >= settings_.min_psnr + kRaiseMargin) {
    ratio_ = std::min(settings_.ratio, ratio_ + 1);
  }
}

UpPlan UpSchedule::key_now(std::uint64_t frame, const scene::SceneState& state, std::string_view why) {
  UpPlan plan;
  plan.draw_key = true;
  plan.why = why;
  // A key drawn ahead for a later frame stays; this one takes the other slot.
  if (second_ && second_->frame <= frame) second_.reset();
  plan.key_slot = second_ ? 1 - second_->slot : 0;
  // Checked only a whole interval on: frames skipped or a cut say nothing of
  // how well the frames between follow the scene.
  if (settings_.adaptive() && first_ && first_->frame + static_cast<std::uint64_t>(ratio_) == frame &&
      same_side(first_->state, state)) {
    plan.check_slot = first_->slot;
  }
  first_ = Key{frame, plan.key_slot, state};
  plan.key_state = &first_->state;
  return plan;
}

UpPlan UpSchedule::plan(std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead) {
  if (!first_ || frame <= first_->frame) {
    second_.reset();  // frames that go back start over: a key drawn ahead belongs to another run
    return key_now(frame, state, "first frame");
  }
  if (settings_.mode == config::UpMode::interpolate) return interpolated(frame, state, ahead);
  std::string_view why;
  if (!same_side(first_->state, state, &why)) return key_now(frame, state, why);
  if (frame - first_->frame >= static_cast<std::uint64_t>(ratio_)) return key_now(frame, state, "ratio");
  UpPlan plan;
  plan.between = true;
  plan.frame.method = settings_.method;
  plan.frame.first = first_->slot;
  return plan;
}

UpPlan UpSchedule::interpolated(std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead) {
  if (second_ && frame == second_->frame) {  // drawn ahead for this frame: shown as it is
    UpPlan plan;
    plan.shown_slot = second_->slot;
    first_ = std::move(second_);
    second_.reset();
    return plan;
  }
  if (second_ && frame > second_->frame) return key_now(frame, state, "frames skipped");
  UpPlan plan;
  if (!second_) {
    // The next key frame, as far ahead as the ratio allows and the master sent.
    const std::uint64_t last = first_->frame + static_cast<std::uint64_t>(ratio_);
    if (last <= frame) return key_now(frame, state, "ratio");
    const scene::SceneState* later = nullptr;
    std::uint64_t b = last;
    for (; b > frame && !(later = ahead ? ahead(b) : nullptr); --b) {
    }
    if (later == nullptr) return key_now(frame, state, "nothing ahead");
    std::string_view why;
    if (!same_side(first_->state, state, &why) && !same_side(*later, state)) return key_now(frame, state, why);
    plan.draw_key = true;
    plan.ahead_frame = b;
    plan.key_slot = 1 - first_->slot;
    if (settings_.adaptive() && b == last && same_side(first_->state, *later)) plan.check_slot = first_->slot;
    second_ = Key{b, plan.key_slot, *later};
    plan.key_state = &second_->state;
  }
  // From the key frames on this frame's side of any cut; none: drawn now.
  const bool from_first = same_side(first_->state, state);
  const bool from_second = same_side(second_->state, state);
  if (!from_first && !from_second) {
    std::string_view why;
    (void)same_side(first_->state, state, &why);
    return key_now(frame, state, why);
  }
  plan.between = true;
  plan.frame.method = settings_.method;
  const double span = static_cast<double>(second_->frame - first_->frame);
  const double t = static_cast<double>(frame - first_->frame) / span;
  if (from_first && from_second) {
    plan.frame.first = first_->slot;
    plan.frame.two_keys = true;
    plan.frame.toward_second = t;
  } else {
    plan.frame.first = from_first ? first_->slot : second_->slot;
  }
  return plan;
}

}  // namespace optique::up
