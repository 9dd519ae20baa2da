// The master core's run control (master/protocol.h): draining and stopping,
// the report and the live status, the operator's commands, the tracker's
// input, the local nodes and interrupts.

#include <fmt/format.h>

#include <algorithm>
#include <csignal>

#include "master/protocol.h"
#include "master/run_verdict.h"
#include "scene/state.h"

namespace optique::master {

using clock::nanos;

// ---------------------------------------------------------------- stopping

void MasterProtocol::drain(const std::string& reason, clock::Nanos now, Actions& out) {
  if (state_ != RunState::starting && state_ != RunState::running) return;
  stopped_because_ = reason;
  paused_ = false;
  begin_on_resume_ = false;
  const bool frames_ran = state_ == RunState::running;
  state_ = RunState::draining;
  out.push_back(Disarm{Timer::next_frame});
  out.push_back(Disarm{Timer::startup});
  out.push_back(Log{spdlog::level::info, "stopping: " + reason});
  notify_run(session::RunChanged::STOPPING, reason, out);
  // A frame in its barrier finishes first (swap() then comes back here).
  if (!barrier_.active()) wait_for_last_presents(frames_ran, now, out);
}

void MasterProtocol::wait_for_last_presents(bool frames_ran, clock::Nanos now, Actions& out) {
  // The last swap's Presented arrive after its present deadline.
  const clock::Nanos wait = frames_ran ? nanos(config_.present_lead) + 250 * clock::kNanosPerMilli : 0;
  out.push_back(Arm{Timer::last_presents, now + wait});
}

void MasterProtocol::say_goodbye(clock::Nanos now, Actions& out) {
  if (state_ == RunState::closing || state_ == RunState::done) return;
  state_ = RunState::closing;
  out.push_back(StopAccepting{});
  wire::Envelope envelope;
  envelope.mutable_goodbye()->set_reason(stopped_because_);
  for (const auto& [peer, session] : sessions_) {
    out.push_back(Send{peer, envelope});
    out.push_back(Close{peer, "goodbye", true});
  }
  // Nodes exit on goodbye; whatever is still there after this is stopped harder.
  out.push_back(Arm{Timer::goodbye, now + 3 * clock::kNanosPerSecond});
  finish_if_all_gone(out);
}

void MasterProtocol::fail(const std::string& reason, clock::Nanos now, Actions& out) {
  out.push_back(Log{spdlog::level::err, reason});
  exit_code_ = kExitFailed;
  stopped_because_ = reason;
  say_goodbye(now, out);
}

void MasterProtocol::finish_if_all_gone(Actions& out) {
  if (state_ == RunState::closing && sessions_.empty() && local_running_ == 0) finish(out);
}

void MasterProtocol::finish(Actions& out) {
  if (state_ == RunState::done) return;
  state_ = RunState::done;
  for (Timer t : kTimers) out.push_back(Disarm{t});
  if (auto rows = recorder_.finalize(); !rows.empty()) out.push_back(FrameRows{std::move(rows)});
  const report::RunReport summary = report();
  out.push_back(Log{spdlog::level::info, summary_line(summary)});
  if (exit_code_ == kExitOk) {
    if (auto why = too_few_shown(summary, config_.min_presented)) {
      out.push_back(Log{spdlog::level::err, "the run failed: " + *why});
      exit_code_ = kExitTooFewShown;
    }
  }
  out.push_back(Finish{exit_code_});
}

report::RunReport MasterProtocol::report() const {
  report::RunReport report = recorder_.report();
  report.set_frame_rate(config_.frame_rate);
  report.set_stopped_because(stopped_because_);
  report.set_connections_refused(refused_connections_);
  if (head_) *report.mutable_tracking() = head_->report();
  report.set_instances(current_state_.instances.size());
  report.set_snapshot_bytes(scene::to_snapshot(current_state_).ByteSizeLong());
  return report;
}

LiveStatus MasterProtocol::live(clock::Nanos now) const {
  LiveStatus status;
  switch (state_) {
    case RunState::starting:
      status.state = "starting";
      break;
    case RunState::running:
      status.state = paused_ ? "paused" : "running";
      break;
    case RunState::draining:
    case RunState::closing:
      status.state = "stopping";
      break;
    case RunState::done:
      status.state = "done";
      break;
  }
  status.next_frame = next_frame_;
  status.frames_target = settings_.frames;
  status.target_rate_hz = config_.frame_rate;
  const RunTotals& totals = recorder_.totals();
  status.frames_finalized = totals.frames_finalized;
  status.frames_with_missing_node = totals.frames_with_missing_node;
  status.frames_incoherent = totals.frames_incoherent;
  status.frames_dropped = totals.frames_dropped;
  status.skew_us_sum = totals.present_skew_us_sum;
  status.skew_count = totals.present_skew_count;
  status.nodes_up = nodes_up();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    LiveNode node;
    node.id = slot_id(i);
    node.counts = recorder_.node_counts(i);
    if (const Session* session = session_of(i)) {
      node.peer = session->peer_text;
      switch (session->phase) {
        case Phase::handshake:
          node.link = NodeLink::connecting;
          break;
        case Phase::configuring:
          node.link = NodeLink::configuring;
          break;
        case Phase::joined:
        case Phase::in_barrier:
          node.link = NodeLink::up;
          break;
        case Phase::out_of_barrier:
          node.link = NodeLink::behind;
          break;
      }
    } else {
      node.link = node.counts.joins > 0 ? NodeLink::gone : NodeLink::absent;
    }
    status.nodes.push_back(std::move(node));
  }
  if (head_) status.tracking = head_->report();
  summarize_recent(recorder_.recent(), now, status);
  return status;
}

void MasterProtocol::notify_run(session::RunChanged::State run, const std::string& reason, Actions& out) const {
  if (settings_.live == nullptr) return;
  session::Event event;
  event.mutable_run()->set_state(run);
  event.mutable_run()->set_frame(next_frame_);
  event.mutable_run()->set_reason(reason);
  out.push_back(AppEvent{std::move(event)});
}

void MasterProtocol::notify_node(std::size_t slot, bool up, const std::string& reason, Actions& out) const {
  if (settings_.live == nullptr) return;
  session::Event event;
  auto& node = *event.mutable_node();
  node.set_projector(slot_id(slot));
  node.set_up(up);
  node.set_reason(reason);
  node.set_nodes_up(static_cast<std::uint32_t>(nodes_up()));
  node.set_nodes(static_cast<std::uint32_t>(slots_.size()));
  out.push_back(AppEvent{std::move(event)});
}

Actions MasterProtocol::operator_command(OperatorCommand command, const std::string& from, clock::Nanos now) {
  Actions out;
  const std::string who = "the operator (" + from + ")";
  const auto say = [&](spdlog::level::level_enum level, const std::string& text) { out.push_back(Log{level, text}); };
  switch (command) {
    case OperatorCommand::pause:
      if (state_ != RunState::running) {
        say(spdlog::level::info, who + " asked to pause, but frames are not running");
      } else if (paused_) {
        say(spdlog::level::info, who + " asked to pause: paused already");
      } else {
        paused_ = true;
        say(spdlog::level::warn, fmt::format("paused by {}: no frame after frame {}; every projector keeps showing "
                                             "its last",
                                             who, next_frame_ == 0 ? 0 : next_frame_ - 1));
        notify_run(session::RunChanged::PAUSED, "paused by " + who, out);
      }
      break;
    case OperatorCommand::resume:
      if (state_ != RunState::running) {
        say(spdlog::level::info, who + " asked to resume, but frames are not running");
        break;
      }
      if (!paused_) {
        say(spdlog::level::info, who + " asked to resume, but nothing is paused");
        break;
      }
      paused_ = false;
      say(spdlog::level::warn, fmt::format("resumed by {} at frame {}", who, next_frame_));
      notify_run(session::RunChanged::RUNNING, "resumed by " + who, out);
      if (begin_on_resume_) {
        // The schedule starts again from now: no rush of frames to catch up.
        begin_on_resume_ = false;
        schedule_origin_ = now;
        schedule_origin_frame_ = next_frame_;
        begin_frame(now, out);
      }
      break;
    case OperatorCommand::stop:
      if (state_ != RunState::starting && state_ != RunState::running) {
        say(spdlog::level::info, who + " asked to stop: stopping already");
        break;
      }
      say(spdlog::level::warn, "stop asked by " + who + ": finishing the current frame and shutting down");
      drain("stopped by " + who, now, out);
      break;
  }
  return out;
}

// ---------------------------------------------------------------- the head

Actions MasterProtocol::tracker_input(tracking::TrackerInput input) {
  Actions out;
  if (!head_) return out;
  navigation_.input(input.flysticks);
  std::vector<std::string> said;
  head_->input(std::move(input), said);
  for (std::string& text : said) out.push_back(Log{spdlog::level::warn, std::move(text)});
  return out;
}

Actions MasterProtocol::local_node_exited(const std::string& id, const std::string& how, bool clean,
                                          const std::string& log_hint, clock::Nanos now) {
  Actions out;
  const std::string text = "node '" + id + "' " + how + log_hint;
  out.push_back(Log{state_ == RunState::closing && clean ? spdlog::level::debug : spdlog::level::warn, text});
  if (state_ == RunState::starting && !clean)
    fail("node '" + id + "' stopped before the cluster started" + log_hint, now, out);
  return out;
}

Actions MasterProtocol::local_nodes_running(std::size_t count, clock::Nanos) {
  Actions out;
  local_running_ = count;
  finish_if_all_gone(out);
  return out;
}

Actions MasterProtocol::interrupted(const std::string& signal_name, clock::Nanos now) {
  Actions out;
  ++interrupts_;
  if (interrupts_ == 1) {
    out.push_back(Log{spdlog::level::info,
                      signal_name + ": finishing the current frame and shutting down (again to stop at once)"});
    drain("interrupted (" + signal_name + ")", now, out);
    return out;
  }
  out.push_back(Log{spdlog::level::warn, signal_name + " again: stopping now"});
  out.push_back(SignalLocalNodes{SIGKILL});
  stopped_because_ = "interrupted twice (" + signal_name + ")";
  finish(out);
  return out;
}

}  // namespace optique::master
