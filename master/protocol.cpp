#include "master/protocol.h"

#include <fmt/format.h>

#include <algorithm>
#include <csignal>

#include "net/envelope.h"
#include "net/hello_proof.h"
#include "protocol/scene_fetch.h"
#include "protocol/welcome.h"
#include "util/join.h"

namespace optique::master {

using clock::nanos;

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
      focus_(FocusSchedule::make(installation)),
      navigation_(installation.viewer.navigation, installation.viewer.tracking, authority_.frame_period()) {
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
    out.push_back(Send{peer, net::refusal(reason, retriable)});
    out.push_back(Close{peer, "refused: " + reason, true});
  };
  if (state_ != RunState::starting && state_ != RunState::running) {
    out.push_back(Send{peer, net::refusal("the master is shutting down", true)});
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
      scene_server_.request(peer, slot_id(*session.slot), session.scene, message.scene_request(),
                            session.phase == Phase::configuring, now, out);
      break;
    case wire::Envelope::kAssetReady:
      if (session.phase == Phase::configuring) {
        out.push_back(Close{peer, "said an asset is ready before it was configured"});
        break;
      }
      on_asset_ready(session, message.asset_ready(), out);
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
  out.push_back(Send{peer, net::refusal(reason, retriable)});
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
    auto keys = net::check_hello(*settings_.secret, session.nonce, hello, message.protocol_version(), "node",
                                 "start the node with --secret-file");
    if (!keys) {
      refuse(peer, session, hello.node_id(), keys.error(), false, out);
      return;
    }
    // Everything from here on is sealed, refusals included: the node knows its
    // master by the first message that opens.
    out.push_back(Protect{peer, keys.value()});
  }
  const std::optional<std::size_t> slot = installation_.find_projector(hello.node_id());
  if (!slot) {
    const std::string known = util::joined(installation_.projectors, [](const config::Projector& p) { return p.id; });
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
  // Every asset applications loaded: the node readies them before it says it
  // is configured.
  const std::vector<protocol::AssetOffer> assets = asset_offers();
  for (const protocol::AssetOffer& asset : assets) session.assets_ready.insert(asset.asset);
  *envelope.mutable_welcome() = protocol::encode_welcome(installation_, *slot, scene_.manifest,
                                                         static_cast<std::uint32_t>(scene_.definition.lights.size()),
                                                         frame_period_, share, assets);
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
  recorder_.node_event(*session.slot, NodeEvent::joined);
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
  notify_node(*session.slot, true, "", out);
  if (state_ == RunState::starting && (nodes_up() == slots_.size() || (startup_passed_ && slots_configuring().empty())))
    start_frames(now, out);
}

// The state as of the last frame begun, with the edits staged since; the next
// FrameBegin's delta applies to it.
void MasterProtocol::send_resync(PeerId peer, Actions& out) const {
  wire::Envelope envelope;
  auto& resync = *envelope.mutable_resync();
  *resync.mutable_snapshot() = scene::to_snapshot(current_state_);
  resync.set_next_frame_id(next_frame_);
  resync.set_state_hash(scene::state_hash(current_state_, current_instances_hash_));
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
      if (session.phase != Phase::handshake && session.phase != Phase::configuring) {
        notify_node(slot, false, reason, out);  // it was up
      }
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
    check_assets(out);  // an asset it had not readied yet waits for it no longer
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
        const std::string ids = util::joined(configuring, [&](std::size_t slot) { return slot_id(slot); });
        out.push_back(
            Log{spdlog::level::warn,
                fmt::format("no node ready after {} ms; waiting for {} (connected, still configuring, "
                            "at most {} s each) before starting",
                            config_.startup_timeout.count(), ids, scene_server_.configure_timeout().count())});
        break;
      }
      {
        std::vector<std::string> missing;
        for (std::size_t i = 0; i < slots_.size(); ++i) {
          if (!slots_[i].peer) missing.push_back(slot_id(i));
        }
        out.push_back(Log{spdlog::level::warn,
                          fmt::format("starting without {} (not connected after {} ms); they join when they come",
                                      util::joined(missing), config_.startup_timeout.count())});
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

}  // namespace optique::master
