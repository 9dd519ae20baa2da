#include "master/protocol.h"

#include <fmt/format.h>

#include <algorithm>
#include <csignal>

#include "config/light_list.h"
#include "master/run_verdict.h"
#include "net/envelope.h"
#include "protocol/focus.h"
#include "protocol/scene_fetch.h"
#include "protocol/welcome.h"

namespace optique::master {
namespace {

// A Refuse: its reason, and whether trying again later may get in.
wire::Envelope refusal(const std::string& reason, bool retriable) {
  wire::Envelope envelope;
  envelope.set_protocol_version(net::kProtocolVersion);
  envelope.mutable_refuse()->set_reason(reason);
  envelope.mutable_refuse()->set_retriable(retriable);
  return envelope;
}

using std::chrono::milliseconds;

clock::Nanos nanos(std::chrono::nanoseconds d) { return d.count(); }

}  // namespace

MasterProtocol::MasterProtocol(const config::Installation& installation, const scene::LoadedScene& scene,
                               RunSettings settings, RunRecorder& recorder)
    : installation_(installation),
      config_(installation.master),
      scene_(scene),
      settings_(std::move(settings)),
      recorder_(recorder),
      slots_(installation.projectors.size()),
      authority_(scene.definition.objects, installation.viewer, installation.master.frame_rate,
                 LightSwitches::from_config(installation.scene)),
      scene_server_(scene),
      light_plan_(installation, scene.definition),
      focus_(FocusSchedule::make(installation)) {
  frame_period_ = authority_.frame_period();
  if (installation.viewer.tracking) {
    head_.emplace(*installation.viewer.tracking, installation.viewer.head_right, frame_period_,
                  std::move(settings_.replay));
  }
  current_state_ = authority_.state_at_frame(0);
  current_hash_ = scene::state_hash(current_state_);
  // Until nodes come, plan as if all were up: each node's welcome then carries a
  // sensible share.
  light_plan_.rebalance(std::vector<bool>(slots_.size(), true), current_state_, current_state_.eye_now, true);
}

bool MasterProtocol::up(const Slot& slot) const {
  if (!slot.peer) return false;
  const Phase phase = sessions_.at(*slot.peer).phase;
  return phase != Phase::handshake && phase != Phase::configuring;
}

std::size_t MasterProtocol::nodes_up() const {
  return static_cast<std::size_t>(std::count_if(slots_.begin(), slots_.end(), [&](const Slot& s) { return up(s); }));
}

std::vector<std::size_t> MasterProtocol::slots_configuring() const {
  std::vector<std::size_t> configuring;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (slots_[i].peer && sessions_.at(*slots_[i].peer).phase == Phase::configuring) configuring.push_back(i);
  }
  return configuring;
}

std::string MasterProtocol::slot_id(std::size_t slot) const { return installation_.projectors[slot].id; }

MasterProtocol::Session* MasterProtocol::session_of(std::size_t slot) {
  return slots_[slot].peer ? &sessions_.at(*slots_[slot].peer) : nullptr;
}

const MasterProtocol::Session* MasterProtocol::session_of(std::size_t slot) const {
  return slots_[slot].peer ? &sessions_.at(*slots_[slot].peer) : nullptr;
}

Actions MasterProtocol::start(clock::Nanos now) {
  Actions out;
  if (head_) head_->start(now);
  out.push_back(Arm{Timer::startup, now + nanos(config_.startup_timeout)});
  out.push_back(Arm{Timer::heartbeat, now + nanos(config_.heartbeat)});
  return out;
}

// ---------------------------------------------------------------- connections

Actions MasterProtocol::accepted(PeerId peer, const std::string& peer_text, bool loopback,
                                 const std::vector<std::uint8_t>& nonce, clock::Nanos now) {
  (void)now;
  Actions out;
  // Refused at the door, before any session: the peer is told why (a node stops
  // on a refusal it cannot cure by retrying), and the master logs it.
  const auto refuse_at_door = [&](const std::string& reason, bool retriable) {
    out.push_back(Log{spdlog::level::warn, "refused connection from " + peer_text + ": " + reason});
    ++refused_connections_;
    out.push_back(Send{peer, refusal(reason, retriable)});
    out.push_back(Close{peer, "refused: " + reason, true});
  };
  if (state_ != RunState::starting && state_ != RunState::running) {
    out.push_back(Send{peer, refusal("the master is shutting down", true)});
    out.push_back(Close{peer, "the master is shutting down", true});
    return out;
  }
  if (!settings_.secret && !loopback) {
    refuse_at_door(
        "no shared secret is configured (master.secret_file), so only nodes on this machine are accepted; for nodes "
        "on other hosts, give the master master.secret_file and each node --secret-file",
        false);
    return out;
  }
  const auto pending = static_cast<std::size_t>(std::count_if(
      sessions_.begin(), sessions_.end(), [](const auto& s) { return s.second.phase == Phase::handshake; }));
  if (pending >= config_.max_pending_connections) {
    refuse_at_door(
        fmt::format("{} connections are already waiting to authenticate (master.max_pending_connections)", pending),
        true);
    return out;
  }
  Session& session = sessions_[peer];
  session.peer_text = peer_text;
  session.nonce = nonce;
  // Until a peer has said who it is, only a hello-sized frame is accepted: nobody
  // makes the master parse megabytes before authenticating.
  out.push_back(SetMaxPayload{peer, kMaxHelloBytes});
  out.push_back(SetDeadline{peer, config_.handshake_timeout,
                            "no valid hello within " + std::to_string(config_.handshake_timeout.count()) + " ms"});
  wire::Envelope challenge;
  challenge.mutable_challenge()->set_nonce(nonce.data(), nonce.size());
  challenge.mutable_challenge()->set_secret_required(settings_.secret.has_value());
  out.push_back(Send{peer, std::move(challenge)});
  out.push_back(Log{spdlog::level::debug, "connection from " + peer_text});
  return out;
}

Actions MasterProtocol::message(PeerId peer, const wire::Envelope& message, clock::Nanos now) {
  Actions out;
  const auto found = sessions_.find(peer);
  if (found == sessions_.end()) return out;  // refused, or closed already
  Session& session = found->second;
  if (session.phase == Phase::handshake) {
    on_hello(peer, session, message, now, out);
    return out;
  }
  if (message.protocol_version() != net::kProtocolVersion) {
    out.push_back(Close{peer, "protocol version changed mid-connection"});
    return out;
  }
  switch (message.body_case()) {
    case wire::Envelope::kPing: {
      wire::Envelope pong;
      auto& p = *pong.mutable_pong();
      p.set_t1(message.ping().t1());
      p.set_t2(now);
      // t3 is stamped when the shell hands the pong to the socket (the shell
      // overwrites it); until then, the time of receipt.
      p.set_t3(now);
      out.push_back(Send{peer, std::move(pong)});
      break;
    }
    case wire::Envelope::kHeartbeat:
      break;
    case wire::Envelope::kSceneRequest:
      if (session.phase != Phase::configuring) {
        out.push_back(Close{peer, "asked for the scene's files after setting up"});
        break;
      }
      scene_server_.request(peer, slot_id(*session.slot), session.scene, message.scene_request(), now, out);
      break;
    case wire::Envelope::kSceneWait:
      if (session.phase != Phase::configuring) {
        out.push_back(Close{peer, "waited for the scene after setting up"});
        break;
      }
      scene_server_.wait(peer, slot_id(*session.slot), session.scene, message.scene_wait(), now, out);
      break;
    case wire::Envelope::kConfigured:
      if (session.phase != Phase::configuring) {
        out.push_back(Close{peer, "configured twice"});
        break;
      }
      on_configured(peer, session, message.configured(), now, out);
      break;
    case wire::Envelope::kFrameReady:
      on_ready(session, message.frame_ready(), now, now, out);
      break;
    case wire::Envelope::kPresented:
      on_presented(session, message.presented(), now, out);
      break;
    case wire::Envelope::kGoodbye:
      out.push_back(Close{peer, "node said goodbye (" + message.goodbye().reason() + ")"});
      break;
    default:
      out.push_back(Close{peer, std::string("unexpected ") + net::body_name(message) + " from a node"});
      break;
  }
  return out;
}

void MasterProtocol::refuse(PeerId peer, Session& session, const std::string& node_id, const std::string& reason,
                            bool retriable, Actions& out) {
  out.push_back(Log{spdlog::level::warn, "refused node '" + node_id + "' from " + session.peer_text + ": " + reason});
  session.refused = true;
  ++refused_connections_;
  out.push_back(Send{peer, refusal(reason, retriable)});
  out.push_back(Close{peer, "refused: " + reason, true});
}

void MasterProtocol::on_hello(PeerId peer, Session& session, const wire::Envelope& message, clock::Nanos now,
                              Actions& out) {
  if (message.body_case() == wire::Envelope::kGoodbye) {
    // A node that cannot answer the challenge (it has no secret) says why.
    out.push_back(Log{spdlog::level::warn,
                      "a node at " + session.peer_text + " left before its hello: " + message.goodbye().reason()});
    session.refused = true;
    ++refused_connections_;
    out.push_back(Close{peer, "left before its hello"});
    return;
  }
  if (message.body_case() != wire::Envelope::kHello) {
    refuse(peer, session, "?", std::string("expected hello, got ") + net::body_name(message), false, out);
    return;
  }
  const wire::Hello& hello = message.hello();
  if (message.protocol_version() != net::kProtocolVersion) {
    refuse(peer, session, hello.node_id(),
           "protocol version mismatch: node speaks v" + std::to_string(message.protocol_version()) +
               ", master speaks v" + std::to_string(net::kProtocolVersion) +
               "; run the same optique version on master and nodes",
           false, out);
    return;
  }
  if (settings_.secret) {
    const std::string& mac = hello.nonce_mac();
    if (mac.empty()) {
      refuse(peer, session, hello.node_id(),
             "this master requires the installation's shared secret: start the node with --secret-file", false, out);
      return;
    }
    const std::string& node_nonce = hello.node_nonce();
    if (node_nonce.size() != net::kNonceBytes) {
      refuse(peer, session, hello.node_id(),
             fmt::format("the hello's node nonce has {} bytes, not {}", node_nonce.size(), net::kNonceBytes), false,
             out);
      return;
    }
    std::vector<std::uint8_t> both = session.nonce;
    both.insert(both.end(), node_nonce.begin(), node_nonce.end());
    if (!net::verify_hello_mac(*settings_.secret, both, hello.node_id(), message.protocol_version(),
                               std::span(reinterpret_cast<const std::uint8_t*>(mac.data()), mac.size()))) {
      refuse(peer, session, hello.node_id(), "authentication failed: the node's secret does not match the master's",
             false, out);
      return;
    }
    // Everything from here on is sealed, refusals included: the node knows its
    // master by the first message that opens.
    out.push_back(Protect{
        peer,
        net::derive_session_keys(*settings_.secret, session.nonce,
                                 std::span(reinterpret_cast<const std::uint8_t*>(node_nonce.data()), node_nonce.size()),
                                 hello.node_id(), message.protocol_version())});
  }
  const std::optional<std::size_t> slot = installation_.find_projector(hello.node_id());
  if (!slot) {
    std::string known;
    for (const config::Projector& p : installation_.projectors) known += (known.empty() ? "" : ", ") + p.id;
    refuse(peer, session, hello.node_id(),
           "unknown projector id '" + hello.node_id() + "' (this installation has: " + known + ")", false, out);
    return;
  }
  Slot& target = slots_[*slot];
  if (target.peer) {
    refuse(
        peer, session, hello.node_id(),
        "projector '" + hello.node_id() + "' is already driven by the node at " + sessions_.at(*target.peer).peer_text,
        true, out);
    return;
  }

  target.peer = peer;
  session.slot = slot;
  session.phase = Phase::configuring;
  out.push_back(SetMaxPayload{peer, config_.max_message_bytes});
  // Setting up a GL context and compiling shaders can take seconds on a loaded
  // machine; the node is silent meanwhile.
  out.push_back(SetDeadline{
      peer, scene_server_.configure_timeout(),
      "node did not finish configuring within " + std::to_string(scene_server_.configure_timeout().count()) + " s"});
  const LightShare* share = light_plan_.share(*slot);
  wire::Envelope envelope;
  *envelope.mutable_welcome() =
      protocol::encode_welcome(installation_, *slot, scene_.manifest,
                               static_cast<std::uint32_t>(scene_.definition.lights.size()), frame_period_, share);
  // Its first frame repeats the share, so the log tells from which frame each node
  // draws what (and a share changed while it set itself up still reaches it).
  if (share != nullptr) target.sent_share.reset();
  out.push_back(Send{peer, std::move(envelope)});
  out.push_back(
      Log{spdlog::level::debug, "node '" + hello.node_id() + "' from " + session.peer_text + " is configuring"});
  (void)now;
}

void MasterProtocol::on_configured(PeerId peer, Session& session, const wire::Configured& configured, clock::Nanos now,
                                   Actions& out) {
  out.push_back(CancelDeadline{peer});
  out.push_back(SetLiveness{peer, config_.liveness_timeout,
                            "node silent for " + std::to_string(config_.liveness_timeout.count()) + " ms"});
  send_resync(peer, out);
  session.phase = Phase::joined;
  session.drawing.reset();
  session.pace = RenderPace{};
  // The first frame pays what the warm-up paid (programs, textures): it is
  // waited for as long as the warm-up took, twice over.
  if (configured.warm_up_ns() > 0) session.pace.add(configured.warm_up_ns());
  session.pace.set_capture(configured.capture_ns());
  recorder_.node_joined(*session.slot);
  rebalance_lights(true);
  out.push_back(
      Log{spdlog::level::info,
          fmt::format("node '{}' joined from {} with {}{} ({}/{} up)", slot_id(*session.slot), session.peer_text,
                      configured.renderer(),
                      configured.warm_up_ns() > 0
                          ? fmt::format(", warm-up frame {:.0f} ms",
                                        static_cast<double>(std::min(configured.warm_up_ns(), kLongestRender)) / 1e6)
                          : "",
                      nodes_up(), slots_.size())});
  if (state_ == RunState::starting && (nodes_up() == slots_.size() || (startup_passed_ && slots_configuring().empty())))
    start_frames(now, out);
}

// The state as of the last frame begun; the next FrameBegin's delta applies to it.
void MasterProtocol::send_resync(PeerId peer, Actions& out) const {
  wire::Envelope envelope;
  auto& resync = *envelope.mutable_resync();
  *resync.mutable_snapshot() = scene::to_snapshot(current_state_);
  resync.set_next_frame_id(next_frame_);
  resync.set_state_hash(current_hash_);
  out.push_back(Send{peer, std::move(envelope)});
}

Actions MasterProtocol::closed(PeerId peer, const std::string& reason, clock::Nanos now) {
  Actions out;
  const auto found = sessions_.find(peer);
  if (found == sessions_.end()) {  // refused when it came
    finish_if_all_gone(out);
    return out;
  }
  const Session session = std::move(found->second);
  sessions_.erase(found);
  const bool live = state_ == RunState::starting || state_ == RunState::running;
  if (!session.slot) {
    if (live && !session.refused) {
      out.push_back(Log{spdlog::level::warn, "refused connection from " + session.peer_text + ": " + reason});
      ++refused_connections_;
    }
  } else {
    const std::size_t slot = *session.slot;
    slots_[slot].peer.reset();
    if (live) {
      out.push_back(Log{spdlog::level::warn, fmt::format("node '{}' left: {} ({}/{} up)", slot_id(slot), reason,
                                                         nodes_up(), slots_.size())});
    } else {
      out.push_back(Log{spdlog::level::debug, "node '" + slot_id(slot) + "' closed: " + reason});
    }
    if (state_ == RunState::starting && startup_passed_ && slots_configuring().empty()) {
      if (nodes_up() == 0) {
        fail("no node came up: '" + slot_id(slot) + "', the last one configuring, left: " + reason, now, out);
      } else {
        start_frames(now, out);
      }
    }
    std::erase(ready_for_swap_, slot);  // a node that is gone is not told to swap
    if (state_ != RunState::closing && state_ != RunState::done) rebalance_lights(true);
    if (barrier_.active()) {
      barrier_.leave(slot);
      if (barrier_.complete()) swap(now, out);
    }
    present_owed(slot, now, out);  // nor waited for to show the last one (after its lights moved)
    begin_if_held_frame_may(now, out);
  }
  finish_if_all_gone(out);
  return out;
}

// ---------------------------------------------------------------- timers

Actions MasterProtocol::timer(Timer timer, clock::Nanos now) {
  Actions out;
  switch (timer) {
    case Timer::startup:
      if (state_ != RunState::starting) break;
      if (nodes_up() == 0) {
        const std::vector<std::size_t> configuring = slots_configuring();
        if (configuring.empty()) {
          fail("no node connected within " + std::to_string(config_.startup_timeout.count()) + " ms", now, out);
          break;
        }
        // Connected nodes still setting up are working, not missing: on a loaded
        // machine, or with a large scene, that takes longer than the timeout.
        // Their own configure deadline bounds the wait.
        startup_passed_ = true;
        std::string ids;
        for (const std::size_t slot : configuring) ids += (ids.empty() ? "" : ", ") + slot_id(slot);
        out.push_back(
            Log{spdlog::level::warn,
                fmt::format("no node ready after {} ms; waiting for {} (connected, still configuring, "
                            "at most {} s each) before starting",
                            config_.startup_timeout.count(), ids, scene_server_.configure_timeout().count())});
        break;
      }
      {
        std::string missing;
        for (std::size_t i = 0; i < slots_.size(); ++i) {
          if (!slots_[i].peer) missing += (missing.empty() ? "" : ", ") + slot_id(i);
        }
        out.push_back(Log{spdlog::level::warn,
                          fmt::format("starting without {} (not connected after {} ms); they join when they come",
                                      missing, config_.startup_timeout.count())});
      }
      start_frames(now, out);
      break;
    case Timer::next_frame:
      if (barrier_.active()) break;  // begun already (the last one showed it)
      if (!presents_owed_.empty() && now < presents_grace_end_) {
        // Its time has come, but a node is still to show the last frame: the
        // next one begins when it has (or when it no longer would).
        begin_when_presented_ = true;
        out.push_back(Arm{Timer::next_frame, presents_grace_end_});
        break;
      }
      begin_frame(now, out);
      break;
    case Timer::barrier:
      on_barrier_timeout(now, out);
      break;
    case Timer::last_presents:
      say_goodbye(now, out);
      break;
    case Timer::goodbye:
      if (state_ != RunState::closing) break;
      if (terminating_) {
        out.push_back(SignalLocalNodes{SIGKILL});
        finish(out);
      } else if (local_running_ > 0) {
        out.push_back(Log{spdlog::level::warn, fmt::format("{} local node(s) still running 3 s after goodbye; "
                                                           "terminating them",
                                                           local_running_)});
        out.push_back(SignalLocalNodes{SIGTERM});
        terminating_ = true;
        out.push_back(Arm{Timer::goodbye, now + 2 * clock::kNanosPerSecond});
      } else {
        finish(out);
      }
      break;
    case Timer::heartbeat: {
      if (state_ == RunState::done) break;
      wire::Envelope envelope;
      envelope.mutable_heartbeat()->set_sent_ns(now);
      for (const Slot& slot : slots_) {
        if (up(slot)) out.push_back(Send{*slot.peer, envelope});
      }
      out.push_back(Arm{Timer::heartbeat, now + nanos(config_.heartbeat)});
      break;
    }
  }
  return out;
}

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
  scene::SceneState state = authority_.state_at_frame(frame);
  const clock::Nanos display =
      schedule_origin_ + static_cast<clock::Nanos>(frame + 1 - schedule_origin_frame_) * frame_period_;
  if (head_) {
    std::vector<std::string> said;
    const HeadShown shown = head_->track(state, frame, display, now, said);
    for (std::string& text : said) out.push_back(Log{spdlog::level::warn, std::move(text)});
    out.push_back(shown);
  }
  wire::Envelope envelope;
  auto& begin = *envelope.mutable_frame_begin();
  begin.set_frame_id(frame);
  begin.set_simulation_time_ns(authority_.simulation_time(frame));
  *begin.mutable_delta() = scene::make_delta(current_state_, state);
  const bool lights_switched = begin.delta().lights_off_size() > 0 || begin.delta().lights_on_size() > 0;
  current_state_ = std::move(state);
  current_hash_ = scene::state_hash(current_state_);
  if (lights_switched) log_light_switches(frame, begin.delta(), out);
  begin.set_state_hash(current_hash_);
  const bool captured = settings_.capture_every != 0 && frame % settings_.capture_every == 0;
  begin.set_capture(captured);
  begin.set_present_time_ns(display);
  if (focus_) {
    *begin.mutable_focus() = protocol::to_wire(focus_->at(static_cast<double>(begin.simulation_time_ns()) / 1e9,
                                                          scene_.definition, current_state_, current_state_.eye_now));
  }
  // The scene moves: about once a second, see whether another split of the
  // automatic groups' lights would finish clearly sooner.
  const auto frames_per_second = static_cast<std::uint64_t>(std::max(1.0, config_.frame_rate));
  if (lights_switched) {
    rebalance_lights(true);
  } else if (frame % frames_per_second == 0) {
    rebalance_lights(false);
  }

  // The record of the frame before last is written out now, before the send is
  // stamped: a CSV row is not part of the barrier round.
  if (frame > 1) recorder_.finalize_before(frame - 1);  // the previous frame may still get Presented
  const clock::Nanos begin_sent = settings_.send_clock ? settings_.send_clock() : now;
  std::vector<std::size_t> sent;
  std::vector<std::size_t> waited;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (!up(slots_[i])) continue;
    const PeerId peer = *slots_[i].peer;
    Session& session = sessions_.at(peer);
    // Behind: it would draw this frame only after the one it is drawing, too
    // late for either; it keeps up with the scene and draws the newest frame
    // once it has answered.
    const bool behind = session.phase == Phase::out_of_barrier && session.drawing.has_value();
    if (session.phase == Phase::out_of_barrier && !behind) {
      out.push_back(
          Log{spdlog::level::info, fmt::format("node '{}' is back in the barrier from frame {}", slot_id(i), frame)});
      session.phase = Phase::in_barrier;
    }
    if (session.phase == Phase::joined) session.phase = Phase::in_barrier;
    if (!behind) session.drawing = frame;
    const LightShare* share = light_plan_.share(i);
    const bool new_share = share != nullptr && slots_[i].sent_share != *share;
    const config::UpConversion& up_conversion = installation_.projectors[i].up_conversion;
    const bool interpolates = up_conversion.frames_ahead() > 0;
    if (!new_share && !interpolates && !behind) {
      out.push_back(Send{peer, envelope});
    } else {
      wire::Envelope to_node = envelope;
      to_node.mutable_frame_begin()->set_skip(behind);
      if (new_share) {
        // A new share applies from this frame on, on every node of the group at once.
        *to_node.mutable_frame_begin()->mutable_lights() = protocol::to_wire(*share);
        slots_[i].sent_share = *share;
        out.push_back(Log{spdlog::level::info, fmt::format("node '{}' draws lights [{}]{} from frame {}", slot_id(i),
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
        // A tracked head that far ahead is a prediction that far ahead.
        if (head_) (void)head_->into(ahead_state, display + static_cast<clock::Nanos>(ahead - frame) * frame_period_);
        *begin_ahead.mutable_ahead() = scene::to_snapshot(ahead_state);
        begin_ahead.set_ahead_frame(ahead);
      }
      out.push_back(Send{peer, std::move(to_node)});
    }
    if (behind) continue;
    sent.push_back(i);
    if (session.phase == Phase::in_barrier) waited.push_back(i);
  }
  recorder_.frame_begun(frame, begin_sent, sent);
  next_frame_ = frame + 1;
  ready_for_swap_.clear();
  // Waited for as long as the slowest of them may take (render_pace.h), at
  // least the frame timeout.
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
    session.pace.add(ready.render_ns());
    say_if_slow(session, out);
  }
  if (ready.frame_id() + 1 == next_frame_ && ready.state_hash() != current_hash_) {
    recorder_.hash_mismatch(slot);
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
    recorder_.node_missed_barrier(slot);
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
  // A node shows a frame no later than a period after its deadline (then it is stale).
  presents_grace_end_ = swap.present_deadline_ns() + frame_period_;
  recorder_.swapped(frame, sent, ready_for_swap_);
  ready_for_swap_.clear();
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
  for (Timer t :
       {Timer::startup, Timer::next_frame, Timer::barrier, Timer::last_presents, Timer::goodbye, Timer::heartbeat}) {
    out.push_back(Disarm{t});
  }
  recorder_.finalize_all();
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
  status.frames_finalized = recorder_.frames_finalized();
  status.frames_with_missing_node = recorder_.frames_with_missing_node();
  status.frames_incoherent = recorder_.frames_incoherent();
  status.frames_dropped = recorder_.frames_dropped();
  status.skew_us_sum = recorder_.present_skew_us_sum();
  status.skew_count = recorder_.present_skew_count();
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

// ---------------------------------------------------------------- lights

void MasterProtocol::rebalance_lights(bool force) {
  std::vector<bool> live(slots_.size(), false);
  for (std::size_t i = 0; i < slots_.size(); ++i) live[i] = up(slots_[i]);
  light_plan_.rebalance(live, current_state_, current_state_.eye_now, force);
}

void MasterProtocol::log_light_switches(std::uint64_t frame, const wire::StateDelta& delta, Actions& out) const {
  const auto list = [](const auto& lights) {
    return config::format_light_list(std::vector<std::uint32_t>(lights.begin(), lights.end()));
  };
  std::string what;
  if (delta.lights_off_size() > 0) what = "lights [" + list(delta.lights_off()) + "] go dark";
  if (delta.lights_on_size() > 0) {
    what += (what.empty() ? "" : ", ") + std::string("lights [") + list(delta.lights_on()) + "] come on";
  }
  out.push_back(
      Log{spdlog::level::info, fmt::format("frame {}: {} ({} of {} off)", frame, what, current_state_.lights_off.size(),
                                           scene_.definition.lights.size())});
}

}  // namespace optique::master
