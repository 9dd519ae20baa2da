#include "master/navigation.h"

#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace optique::master {

double beyond_dead_zone(double value, double dead_zone) {
  if (!std::isfinite(value)) return 0.0;  // the parser refuses these; a guard all the same
  const double magnitude = std::min(std::abs(value), 1.0);
  if (magnitude <= dead_zone) return 0.0;
  return std::copysign((magnitude - dead_zone) / (1.0 - dead_zone), value);
}

scene::Pose fly(const scene::Pose& from, const config::Navigation& settings, double x, double y,
                const std::optional<glm::dvec3>& pointing, const glm::dvec3& eyes, double seconds) {
  scene::Pose to = from;
  const double scale = from.scale.x;  // uniform
  if (y != 0.0 && pointing) {
    // Installation metres along the wand, into the world as the installation lies there.
    to.position += from.rotation * (scale * settings.speed * y * seconds * *pointing);
  }
  if (x != 0.0) {
    // Turning about the vertical through the eyes: what is at the eyes stays there.
    const double angle = -x * glm::radians(settings.turn_speed) * seconds;
    const glm::dquat turn = glm::angleAxis(angle, settings.up);
    to.position += to.rotation * (scale * (eyes - turn * eyes));
    to.rotation = glm::normalize(to.rotation * turn);
  }
  return to;
}

ViewerNavigation::ViewerNavigation(std::optional<config::Navigation> navigation,
                                   std::optional<config::Tracking> tracking, clock::Nanos period)
    : settings_(std::move(navigation)),
      tracking_(std::move(tracking)),
      seconds_(static_cast<double>(period) / static_cast<double>(clock::kNanosPerSecond)) {}

void ViewerNavigation::input(const std::vector<tracking::FlystickSample>& flysticks) {
  for (const tracking::FlystickSample& sample : flysticks) {
    auto found = sticks_.find(sample.id);
    if (found == sticks_.end()) {
      if (sticks_.size() >= kMostFlysticks) continue;
      found = sticks_.emplace(sample.id, Stick{sample, std::nullopt, true}).first;
    }
    Stick& stick = found->second;
    // Anything but its arrival differs: worth an event.
    tracking::FlystickSample as_before = sample;
    as_before.arrival = stick.newest.arrival;
    stick.changed = stick.changed || !(as_before == stick.newest);
    stick.newest = sample;
    if (sample.seen && tracking_) {
      stick.seen = tracking::to_installation(*tracking_, sample.position * 0.001, glm::quat_cast(sample.rotation));
    }
  }
}

namespace {

session::Event flystick_event(std::uint64_t frame, std::uint32_t id, const tracking::FlystickSample& newest,
                              const std::optional<tracking::InstallationPose>& seen) {
  session::Event event;
  session::FlystickChanged& changed = *event.mutable_flystick();
  changed.set_frame(frame);
  changed.set_flystick(id);
  changed.set_seen(newest.seen);
  const tracking::InstallationPose pose = seen.value_or(tracking::InstallationPose{});
  for (int i = 0; i < 3; ++i) changed.add_position(pose.position[i]);
  for (double q : {pose.turn.w, pose.turn.x, pose.turn.y, pose.turn.z}) changed.add_rotation(q);
  for (bool pressed : newest.buttons) changed.add_buttons(pressed);
  for (double value : newest.controllers) changed.add_joystick(value);
  return event;
}

}  // namespace

void ViewerNavigation::step(std::uint64_t frame, scene::SceneState& state, std::uint64_t sets,
                            std::vector<session::Event>& events) {
  for (auto& [id, stick] : sticks_) {
    if (!stick.changed) continue;
    stick.changed = false;
    events.push_back(flystick_event(frame, id, stick.newest, stick.seen));
  }
  if (sets != sets_seen_) {  // an application put it somewhere: from there on
    at_ = home_ = state.navigation.now;
    sets_seen_ = sets;
  }
  if (!settings_ || settings_->mode != config::NavigationMode::flystick) return;
  scene::Pose now = at_;
  double x = 0.0;
  double y = 0.0;
  std::optional<glm::dvec3> pointing;
  if (const auto found = sticks_.find(settings_->flystick); found != sticks_.end()) {
    const Stick& stick = found->second;
    const std::vector<bool>& buttons = stick.newest.buttons;
    const bool pressed = settings_->reset_button < buttons.size() && buttons[settings_->reset_button];
    if (pressed && !reset_held_) now = home_;
    reset_held_ = pressed;
    const std::vector<double>& axes = stick.newest.controllers;
    if (!axes.empty()) x = beyond_dead_zone(axes[0], settings_->dead_zone);
    if (axes.size() > 1) y = beyond_dead_zone(axes[1], settings_->dead_zone);
    if (stick.newest.seen && stick.seen) pointing = stick.seen->turn * settings_->pointer;
  }
  const scene::Pose next = fly(now, *settings_, x, y, pointing, state.eye_now, seconds_);
  state.navigation = {now, next};
  at_ = next;
}

}  // namespace optique::master
