// The master core's frame loop (master/protocol.h): each frame begun (its
// state, what each node is sent), the barrier waited for, the swap, the
// presents; and the lights each node draws. The connections are in
// protocol.cpp, stopping and the reports in run_control.cpp.

#include <fmt/format.h>

#include <algorithm>

#include "config/light_list.h"
#include "master/protocol.h"
#include "protocol/focus.h"
#include "protocol/welcome.h"
#include "scene/instance_tree.h"

namespace optique::master {

using clock::nanos;

// ---------------------------------------------------------------- frames

void MasterProtocol::start_frames(clock::Nanos now, Actions& out) {
  if (state_ != RunState::starting) return;
  state_ = RunState::running;
  out.push_back(Disarm{Timer::startup});
  out.push_back(
      Log{spdlog::level::info,
          fmt::format("starting frames at {} Hz with {}/{} node(s){}", config_.frame_rate, nodes_up(), slots_.size(),
                      settings_.frames ? " for " + std::to_string(settings_.frames) + " frames" : "")});
  schedule_origin_ = now;
  schedule_origin_frame_ = next_frame_;
  begin_frame(now, out);
}

void MasterProtocol::begin_frame(clock::Nanos now, Actions& out) {
  if (state_ != RunState::running) return;
  if (paused_) {
    begin_on_resume_ = true;
    return;
  }
  begin_when_presented_ = false;
  presents_owed_.clear();
  const std::uint64_t frame = next_frame_;
  if (settings_.frames != 0 && frame >= settings_.frames) {
    drain("ran " + std::to_string(settings_.frames) + " frames", now, out);
    return;
  }
  if (all_behind()) {
    if (!begin_when_answered_) {
      out.push_back(
          Log{spdlog::level::warn, fmt::format("frame {} waits: every node is still drawing an earlier frame", frame)});
    }
    begin_when_answered_ = true;
    return;
  }
  if (begin_when_answered_) {
    // The schedule starts again from now: no rush of frames to catch up.
    begin_when_answered_ = false;
    schedule_origin_ = now;
    schedule_origin_frame_ = frame;
  }
  const clock::Nanos display =
      schedule_origin_ + static_cast<clock::Nanos>(frame + 1 - schedule_origin_frame_) * frame_period_;
  const bool captured = settings_.capture_every != 0 && frame % settings_.capture_every == 0;
  // One message for every node that needs nothing of its own in it.
  const auto envelope = std::make_shared<const wire::Envelope>(next_frame_begin(frame, display, captured, now, out));

  const clock::Nanos begin_sent = settings_.send_clock ? settings_.send_clock() : now;
  std::vector<std::size_t> sent;
  std::vector<std::size_t> waited;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!up(slots_[i])) continue;
    if (!send_frame_begin(i, envelope, now, display, out)) continue;
    sent.push_back(i);
    if (session_of(i)->phase == Phase::in_barrier) waited.push_back(i);
  }
  recorder_.frame_begun(frame, begin_sent, sent, envelope->ByteSizeLong());
  next_frame_ = frame + 1;
  ready_for_swap_.clear();
  wait_for(frame, std::move(waited), captured, now, out);
}

// For the scene session's subscribers: the frame begun and the head in it.
void MasterProtocol::notify_frame(std::uint64_t frame, clock::Nanos display, const scene::SceneState& state,
                                  bool tracked, Actions& out) const {
  session::Event begun;
  begun.mutable_frame_begun()->set_frame(frame);
  begun.mutable_frame_begun()->set_display_ns(display);
  begun.mutable_frame_begun()->set_period_ns(frame_period_);
  out.push_back(AppEvent{std::move(begun)});
  session::Event head;
  auto& shown = *head.mutable_head();
  shown.set_frame(frame);
  const glm::dvec3 right = glm::normalize(state.head_now * installation_.viewer.head_right);
  for (int i = 0; i < 3; ++i) {
    shown.add_eyes(state.eye_now[i]);
    shown.add_right(right[i]);
  }
  shown.set_tracked(tracked);
  to_transform(state.navigation.now, *shown.mutable_navigation());
  out.push_back(AppEvent{std::move(head)});
}

// The scene at `frame` (the head where it will be at `display`), as the
// FrameBegin every node is sent: the change from the frame before, its hash,
// when to show it, the focus; the automatic groups' lights planned anew where
// the scene asks for it.
wire::Envelope MasterProtocol::next_frame_begin(std::uint64_t frame, clock::Nanos display, bool captured,
                                                clock::Nanos now, Actions& out) {
  scene::SceneState state = authority_.state_at_frame(frame);
  if (settings_.live != nullptr) {
    if (settings_.journal_replay != nullptr) {
      for (std::string& problem : settings_.journal_replay->apply_due(*settings_.live, frame)) {
        out.push_back(Log{spdlog::level::warn, std::move(problem)});
      }
    }
    // Every edit made until now is in this frame; the next frame's budget of edits starts.
    put_live_lights(*settings_.live, state);  // the instances: below, as they changed
    settings_.live->begin_frame();
  }
  bool tracked = false;
  if (head_) {
    std::vector<std::string> said;
    const HeadShown shown = head_->track(state, frame, display, now, said);
    for (std::string& text : said) out.push_back(Log{spdlog::level::warn, std::move(text)});
    tracked = shown.tracker == tracking::TrackerState::tracking;
    out.push_back(shown);
  }
  std::vector<session::Event> flysticks;
  navigation_.step(frame, state, settings_.live != nullptr ? settings_.live->navigation().sets : 0, flysticks);
  if (settings_.live != nullptr) {
    notify_frame(frame, display, state, tracked, out);
    for (session::Event& event : flysticks) out.push_back(AppEvent{std::move(event)});
  }
  wire::Envelope envelope;
  auto& begin = *envelope.mutable_frame_begin();
  begin.set_frame_id(frame);
  begin.set_simulation_time_ns(authority_.simulation_time(frame));
  *begin.mutable_delta() = scene::make_delta(current_state_, state, false);
  if (settings_.live != nullptr) {
    // The instances staged, with the edits since and the clocks that play.
    std::set<std::string> changed = settings_.live->take_edited();
    changed.insert(settings_.live->playing().begin(), settings_.live->playing().end());
    begin.mutable_delta()->MergeFrom(take_live_instances(changed, frame));
  }
  // A light added or removed is one more or fewer to share out, now: until
  // then no node of a stacked group would draw it.
  const bool lights_added =
      begin.delta().point_lights_removed_size() > 0 ||
      std::any_of(begin.delta().point_lights_set().begin(), begin.delta().point_lights_set().end(),
                  [&](const wire::PointLightState& l) { return !current_state_.point_lights.contains(l.light()); });
  const bool lights_switched = begin.delta().lights_off_size() > 0 || begin.delta().lights_on_size() > 0;
  state.instances = std::move(current_state_.instances);
  current_state_ = std::move(state);
  current_hash_ = scene::state_hash(current_state_, current_instances_hash_);
  if (lights_switched || lights_added) log_light_switches(frame, begin.delta(), out);
  begin.set_state_hash(current_hash_);
  begin.set_capture(captured);
  begin.set_present_time_ns(display);
  if (focus_) {
    *begin.mutable_focus() = protocol::to_wire(focus_->at(static_cast<double>(begin.simulation_time_ns()) / 1e9,
                                                          scene_.definition, current_state_, current_state_.eye_now));
  }
  // The scene moves: about once a second, see whether another split of the
  // automatic groups' lights would finish clearly sooner.
  const auto frames_per_second = static_cast<std::uint64_t>(std::max(1.0, config_.frame_rate));
  if (lights_switched || lights_added) {
    rebalance_lights(true);
  } else if (frame % frames_per_second == 0) {
    rebalance_lights(false);
  }
  return envelope;
}

// Sends the FrameBegin to the node of `slot`, with what is its own: a new share
// of the lights, the frame its key frame is drawn for ahead, or that it is to
// skip this frame. False when it is behind (told to skip; not waited for).
bool MasterProtocol::send_frame_begin(std::size_t slot, const std::shared_ptr<const wire::Envelope>& envelope,
                                      clock::Nanos now, clock::Nanos display, Actions& out) {
  const PeerId peer = *slots_[slot].peer;
  Session& session = sessions_.at(peer);
  const std::uint64_t frame = envelope->frame_begin().frame_id();
  // Behind: it would draw this frame only after the one it is drawing, too
  // late for either; it keeps up with the scene and draws the newest frame
  // once it has answered.
  const bool behind = session.phase == Phase::out_of_barrier && session.drawing.has_value();
  if (session.phase == Phase::out_of_barrier && !behind) {
    out.push_back(
        Log{spdlog::level::info, fmt::format("node '{}' is back in the barrier from frame {}", slot_id(slot), frame)});
    session.phase = Phase::in_barrier;
  }
  if (session.phase == Phase::joined) session.phase = Phase::in_barrier;
  if (!behind) {
    session.drawing = frame;
    session.drawing_since = now;
  }
  const LightShare* share = light_plan_.share(slot);
  const bool new_share = share != nullptr && slots_[slot].sent_share != *share;
  const config::UpConversion& up_conversion = installation_.projectors[slot].up_conversion;
  const bool interpolates = up_conversion.frames_ahead() > 0;
  if (!new_share && !interpolates && !behind) {
    out.push_back(Send{peer, {}, envelope});
    return true;
  }
  wire::Envelope to_node = *envelope;
  to_node.mutable_frame_begin()->set_skip(behind);
  if (new_share) {
    // A new share applies from this frame on, on every node of the group at once.
    *to_node.mutable_frame_begin()->mutable_lights() = protocol::to_wire(*share);
    slots_[slot].sent_share = *share;
    out.push_back(Log{spdlog::level::info, fmt::format("node '{}' draws lights [{}]{} from frame {}", slot_id(slot),
                                                       config::format_light_list(share->lights),
                                                       share->ambient ? " and ambient" : "", frame)});
  }
  if (interpolates) {
    // The scene is a function of time: the frame its next key frame may be
    // drawn for is sent now, ratio − 1 frames before its turn (2·ratio − 1
    // where the key frames are drawn a band a frame).
    const std::uint64_t ahead = frame + static_cast<std::uint64_t>(up_conversion.frames_ahead());
    auto& begin_ahead = *to_node.mutable_frame_begin();
    scene::SceneState ahead_state = authority_.state_at_frame(ahead);
    // Live edits cannot be known ahead: the key frame has the instances as
    // they are now, and an edit reaches it `ahead - frame` frames late.
    ahead_state.instances = current_state_.instances;
    // A tracked head that far ahead is a prediction that far ahead.
    if (head_) (void)head_->into(ahead_state, display + static_cast<clock::Nanos>(ahead - frame) * frame_period_);
    *begin_ahead.mutable_ahead() = scene::to_snapshot(ahead_state);
    begin_ahead.set_ahead_frame(ahead);
  }
  out.push_back(Send{peer, std::move(to_node)});
  return !behind;
}

// The barrier of `frame`, just begun, over the nodes in it: waited for as long
// as the slowest of them may take (render_pace.h), at least the frame timeout.
void MasterProtocol::wait_for(std::uint64_t frame, std::vector<std::size_t> waited, bool captured, clock::Nanos now,
                              Actions& out) {
  barrier_allowance_ = nanos(config_.frame_timeout);
  for (const std::size_t slot : waited) {
    // At most the liveness timeout: a node drawing longer than that is gone anyway.
    barrier_allowance_ = std::max(
        barrier_allowance_,
        session_of(slot)->pace.allowance(nanos(config_.frame_timeout), nanos(config_.liveness_timeout), captured));
  }
  barrier_.begin(frame, std::move(waited));
  if (barrier_.complete()) {
    swap(now, out);
    return;
  }
  out.push_back(Arm{Timer::barrier, now + barrier_allowance_});
}

// A frame held while every node was behind begins once one is not (it
// answered, or the behind ones left); begin_frame starts the schedule anew.
void MasterProtocol::begin_if_held_frame_may(clock::Nanos now, Actions& out) {
  if (!begin_when_answered_ || all_behind()) return;
  out.push_back(Disarm{Timer::next_frame});
  begin_frame(now, out);
}

bool MasterProtocol::all_behind() const {
  bool any_up = false;
  for (const Slot& slot : slots_) {
    if (!up(slot)) continue;
    any_up = true;
    const Session& session = sessions_.at(*slot.peer);
    if (session.phase != Phase::out_of_barrier || !session.drawing) return false;
  }
  return any_up;
}

void MasterProtocol::say_if_slow(Session& session, Actions& out) {
  if (session.said_slow) return;  // once: the median is not worked out on every ready after that
  const std::optional<clock::Nanos> usual = session.pace.typical();
  if (!usual || *usual <= frame_period_) return;
  session.said_slow = true;
  out.push_back(Log{
      spdlog::level::warn,
      fmt::format("node '{}' draws a frame in {:.1f} ms, longer than the {:.1f} ms frame period: frames "
                  "come at the rate it can draw (about {:.1f} Hz), not at {} Hz",
                  slot_id(*session.slot), static_cast<double>(*usual) / 1e6, static_cast<double>(frame_period_) / 1e6,
                  1e9 / static_cast<double>(*usual), config_.frame_rate)});
}

void MasterProtocol::on_ready(Session& session, const wire::FrameReady& ready, clock::Nanos received, clock::Nanos now,
                              Actions& out) {
  const std::size_t slot = *session.slot;
  recorder_.ready(ready.frame_id(), slot, received, ready.render_ns(), ready.drawn_as());
  const bool answers_drawing = session.drawing && ready.frame_id() >= *session.drawing;
  if (answers_drawing) {
    session.drawing.reset();
    session.pace.add(ready.render_ns(), received - session.drawing_since);
    say_if_slow(session, out);
  }
  if (ready.frame_id() + 1 == next_frame_ && ready.state_hash() != current_hash_) {
    recorder_.node_event(slot, NodeEvent::hash_mismatch);
    out.push_back(Log{spdlog::level::warn,
                      fmt::format("node '{}' reports state hash {:016x} for frame {}, master has {:016x}: sending it "
                                  "a fresh snapshot",
                                  slot_id(slot), ready.state_hash(), ready.frame_id(), current_hash_)});
    send_resync(*slots_[slot].peer, out);  // the next FrameBegin's delta applies to it, so the next frame matches
  }
  const bool current = barrier_.active() && ready.frame_id() == barrier_.frame();
  if (session.phase == Phase::out_of_barrier) {
    // It answers again: the next frame is drawn by it and waited for (begin_frame
    // takes it back), and if this answer is for the frame being decided, it
    // swaps with the others.
    if (answers_drawing) {
      out.push_back(Log{spdlog::level::info,
                        fmt::format("node '{}' answers again (frame {}); back in the barrier from the next frame",
                                    slot_id(slot), ready.frame_id())});
    }
    if (current) ready_for_swap_.push_back(slot);
  } else if (current && barrier_.ready(slot)) {
    ready_for_swap_.push_back(slot);
  }
  if (!current) {
    out.push_back(
        Log{spdlog::level::debug, fmt::format("late ready from '{}' for frame {}", slot_id(slot), ready.frame_id())});
  }
  if (barrier_.complete()) swap(now, out);
  begin_if_held_frame_may(now, out);
}

void MasterProtocol::on_barrier_timeout(clock::Nanos now, Actions& out) {
  if (!barrier_.active()) return;
  const bool drop = config_.straggler_policy == config::StragglerPolicy::drop;
  for (std::size_t slot : barrier_.waiting_for()) {
    recorder_.node_event(slot, NodeEvent::missed_barrier);
    if (Session* session = session_of(slot)) session->phase = Phase::out_of_barrier;
    out.push_back(Log{spdlog::level::warn,
                      fmt::format("node '{}' was not ready for frame {} within {} ms: taken out of the barrier; {}",
                                  slot_id(slot), barrier_.frame(), barrier_allowance_ / clock::kNanosPerMilli,
                                  drop ? "the frame is dropped everywhere" : "the others show the frame")});
  }
  if (drop) {
    recorder_.frame_dropped(barrier_.frame());
    ready_for_swap_.clear();  // nobody shows it: every projector keeps the previous frame
  }
  swap(now, out);
}

void MasterProtocol::swap(clock::Nanos now, Actions& out) {
  out.push_back(Disarm{Timer::barrier});
  const std::uint64_t frame = barrier_.frame();
  barrier_.end();
  wire::Envelope envelope;
  auto& swap = *envelope.mutable_swap();
  swap.set_frame_id(frame);
  const clock::Nanos sent = settings_.send_clock ? settings_.send_clock() : now;
  swap.set_present_deadline_ns(sent + nanos(config_.present_lead));
  presents_owed_.clear();
  for (std::size_t slot : ready_for_swap_) {
    if (!slots_[slot].peer) continue;
    out.push_back(Send{*slots_[slot].peer, envelope});
    presents_owed_.push_back(slot);
  }
  presents_owed_frame_ = frame;
  stage_edits(out);  // what came in the round
  // A node shows a frame no later than a period after its deadline (then it is stale).
  presents_grace_end_ = swap.present_deadline_ns() + frame_period_;
  recorder_.swapped(frame, sent, ready_for_swap_);
  ready_for_swap_.clear();
  // The record of the frame before last is complete (the last one may still get
  // Presented). Its rows are written after the Swap has gone: not inside a
  // barrier round (FrameBegin to Swap), where the write would hold up the Swap.
  if (frame > 1) {
    if (auto rows = recorder_.finalize(frame - 1); !rows.empty()) out.push_back(FrameRows{std::move(rows)});
  }
  if (state_ == RunState::draining) {
    wait_for_last_presents(true, now, out);
    return;
  }
  clock::Nanos due = schedule_origin_ + static_cast<clock::Nanos>(next_frame_ - schedule_origin_frame_) * frame_period_;
  if (due < now) {
    // Behind schedule: start again from now instead of rushing frames to catch up.
    schedule_origin_ = now;
    schedule_origin_frame_ = next_frame_;
    due = now;
  }
  out.push_back(Arm{Timer::next_frame, due});
}

void MasterProtocol::on_presented(Session& session, const wire::Presented& presented, clock::Nanos now, Actions& out) {
  if (presented.frame_id() == presents_owed_frame_) present_owed(*session.slot, now, out);
  recorder_.presented(presented.frame_id(), *session.slot, presented.presented_ns(), presented.content_frame_id());
  report::ClockReport clock;
  clock.set_offset_ns(presented.clock_offset_ns());
  clock.set_drift_ppm(presented.clock_drift_ppm());
  clock.set_round_trip_ns(presented.clock_rtt_ns());
  clock.set_error_bound_ns(presented.clock_error_bound_ns());
  recorder_.clock_estimated(
      presented.frame_id(), *session.slot, clock,
      presented.clock_truth_known() ? std::optional(presented.clock_true_error_ns()) : std::nullopt);
}

void MasterProtocol::present_owed(std::size_t slot, clock::Nanos now, Actions& out) {
  if (std::erase(presents_owed_, slot) == 0 || !presents_owed_.empty() || !begin_when_presented_) return;
  out.push_back(Disarm{Timer::next_frame});
  begin_frame(now, out);
}

// ---------------------------------------------------------------- lights

void MasterProtocol::rebalance_lights(bool force) {
  std::vector<bool> live(slots_.size(), false);
  for (std::size_t i = 0; i < slots_.size(); ++i) live[i] = up(slots_[i]);
  // The lights' costs are judged from where the eyes are in the world.
  const glm::dvec3 eye(scene::installation_to_world(current_state_, 0.0) * glm::dvec4(current_state_.eye_now, 1.0));
  light_plan_.rebalance(live, current_state_, eye, force);
}

void MasterProtocol::log_light_switches(std::uint64_t frame, const wire::StateDelta& delta, Actions& out) const {
  const auto list = [](const auto& lights) {
    return config::format_light_list(std::vector<std::uint32_t>(lights.begin(), lights.end()));
  };
  std::string what;
  const auto also = [&](const std::string& more) { what += (what.empty() ? "" : ", ") + more; };
  if (delta.lights_off_size() > 0) also("lights [" + list(delta.lights_off()) + "] go dark");
  if (delta.lights_on_size() > 0) also("lights [" + list(delta.lights_on()) + "] come on");
  std::vector<std::uint32_t> set;
  for (const wire::PointLightState& l : delta.point_lights_set()) set.push_back(l.light());
  if (!set.empty()) also("lights [" + list(set) + "] added or changed");
  if (delta.point_lights_removed_size() > 0) also("lights [" + list(delta.point_lights_removed()) + "] removed");
  out.push_back(
      Log{spdlog::level::info, fmt::format("frame {}: {} ({} of {} off)", frame, what, current_state_.lights_off.size(),
                                           scene_.definition.lights.size() + current_state_.point_lights.size())});
}

}  // namespace optique::master
