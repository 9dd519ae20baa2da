#include "up/schedule.h"

#include <algorithm>
#include <cassert>
#include <cmath>

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
  // A light added, moved or removed shades every surface anew: no key frame
  // drawn before shows it.
  if (key.point_lights != state.point_lights) {
    if (why) *why = "lights added or changed";
    return false;
  }
  if (glm::distance(key.eye_now, state.eye_now) > kCutEyeJump) {
    if (why) *why = "viewer jumped";
    return false;
  }
  // A navigation that jumps (a reset, an application that sets it) is a cut
  // too; one that glides is a moving viewpoint, which the motion fields follow.
  const scene::Pose& a = key.navigation.now;
  const scene::Pose& b = state.navigation.now;
  if (glm::distance(a.position, b.position) > kCutEyeJump || a.scale != b.scale ||
      std::abs(glm::dot(a.rotation, b.rotation)) < kCutTurnCosine) {
    if (why) *why = "navigation jumped";
    return false;
  }
  return true;
}

UpSchedule::UpSchedule(const config::UpConversion& settings) : settings_(settings), ratio_(settings.ratio) {}

void UpSchedule::forget() {
  first_.reset();
  second_.reset();
  building_.reset();
}

void UpSchedule::drop_band() { building_.reset(); }

void UpSchedule::checked(double psnr_y) {
  if (!settings_.adaptive()) return;
  if (psnr_y < settings_.min_psnr) {
    ratio_ = std::max(1, ratio_ - 1);
  } else if (psnr_y >= settings_.min_psnr + kRaiseMargin) {
    ratio_ = std::min(settings_.ratio, ratio_ + 1);
  }
}

int UpSchedule::free_slot() const {
  for (int slot = 0; slot < slots(); ++slot) {
    const bool used = (first_ && first_->slot == slot) || (second_ && second_->slot == slot) ||
                      (building_ && building_->key.slot == slot);
    if (!used) return slot;
  }
  assert(false && "more key frames than slots");
  return 0;
}

UpPlan UpSchedule::key_now(std::uint64_t frame, const scene::SceneState& state, std::string_view why) {
  UpPlan plan;
  plan.draw_key = true;
  plan.why = why;
  // A key frame drawn in bands is begun again after this one (it may be of the
  // other side of a cut, or late).
  building_.reset();
  // A key drawn ahead for a later frame stays; this one takes another slot.
  if (second_ && second_->frame <= frame) second_.reset();
  plan.key_slot = 0;
  while (second_ && plan.key_slot == second_->slot) ++plan.key_slot;
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
  // A key frame whose last band was drawn is kept from this frame on.
  if (building_ && building_->next == building_->count) {
    if (settings_.mode == config::UpMode::extrapolate) {
      first_ = std::move(building_->key);
      building_.reset();
    } else if (!second_) {
      second_ = std::move(building_->key);
      building_.reset();
    }
  }
  if (!first_ || frame <= first_->frame) {
    second_.reset();  // frames that go back start over: a key drawn ahead belongs to another run
    return key_now(frame, state, "first frame");
  }
  UpPlan plan =
      settings_.mode == config::UpMode::interpolate ? interpolated(frame, state, ahead) : extrapolated(frame, state);
  if (settings_.spread && !plan.draw_key) add_band(plan, frame, state, ahead);
  return plan;
}

UpPlan UpSchedule::extrapolated(std::uint64_t frame, const scene::SceneState& state) {
  std::string_view why;
  if (!same_side(first_->state, state, &why)) return key_now(frame, state, why);
  // Spread, a key frame is used from ratio to 2·ratio − 1 frames after its
  // moment (a frame or two more where frames were skipped); much older, or
  // with every frame a key frame (the adaptive ratio at 1), one is drawn now.
  const int oldest = settings_.spread && ratio_ > 1 ? 3 * ratio_ : ratio_;
  if (frame - first_->frame >= static_cast<std::uint64_t>(oldest)) return key_now(frame, state, "ratio");
  UpPlan plan;
  plan.between = true;
  plan.frame.method = settings_.method;
  plan.frame.first = first_->slot;
  return plan;
}

void UpSchedule::add_band(UpPlan& plan, std::uint64_t frame, const scene::SceneState& state, const Ahead& ahead) {
  // Extrapolated, a key frame begun before a cut shows the other side to the
  // frames that will use it: begun again. (Interpolated, it is a later frame's,
  // and the frames between weigh each key frame's side themselves.)
  const bool extrapolates = settings_.mode == config::UpMode::extrapolate;
  if (extrapolates && building_ && !same_side(building_->key.state, state)) building_.reset();
  if (!building_) {
    if (extrapolates) {
      // This frame's key frame, in the next ratio frames.
      building_ = Building{Key{frame, free_slot(), state}, 0, ratio_, frame + static_cast<std::uint64_t>(ratio_) - 1};
    } else {
      // The key frame after the next, in the frames up to the one that shows
      // the next: from the scene sent ahead for it.
      if (!second_) return;
      const std::uint64_t target = second_->frame + static_cast<std::uint64_t>(ratio_);
      const scene::SceneState* later = ahead ? ahead(target) : nullptr;
      if (later == nullptr || !same_side(second_->state, *later)) return;  // drawn at once when its turn comes
      building_ =
          Building{Key{target, free_slot(), *later}, 0, static_cast<int>(second_->frame - frame) + 1, second_->frame};
    }
  }
  Building& b = *building_;
  // A band a frame; on the frame it is due (frames were skipped), all it lacks.
  const int bands = frame >= b.due ? b.count - b.next : 1;
  plan.band = UpPlan::Band{b.key.slot, b.next, b.count, bands, b.key.frame, &b.key.state};
  b.next += bands;
  if (plan.band->last() && settings_.adaptive()) {
    // How the frames between would have followed the scene to this key frame:
    // from the key frame before it, a whole interval on (interpolated, the last
    // band is drawn with the frame that shows that one: first_ by now).
    const Key& before = *first_;
    if (before.frame + static_cast<std::uint64_t>(ratio_) == b.key.frame && same_side(before.state, b.key.state)) {
      plan.check_slot = before.slot;
    }
  }
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
    building_.reset();  // begun for another key frame after the next
    plan.draw_key = true;
    plan.ahead_frame = b;
    plan.key_slot = free_slot();
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
    plan.frame.second = second_->slot;
    plan.frame.two_keys = true;
    plan.frame.toward_second = t;
    plan.frame.per_frame = 1.0 / span;
  } else {
    plan.frame.first = from_first ? first_->slot : second_->slot;
  }
  return plan;
}

}  // namespace optique::up
