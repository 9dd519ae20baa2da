#include "node/protocol.h"

#include <fmt/format.h>

#include <algorithm>

#include "net/hello_proof.h"
#include "util/overloaded.h"

namespace optique::node {

using std::chrono::milliseconds;

NodeProtocol::NodeProtocol(NodeSettings settings) : settings_(std::move(settings)) {}

void NodeProtocol::log(Actions& out, spdlog::level::level_enum level, std::string text) const {
  out.push_back(Log{level, std::move(text)});
}

void NodeProtocol::stop(int exit_code, const std::string& reason, Actions& out) {
  if (phase_ == Phase::stopped) return;
  // An unfinished copy stays (its lock let go): the next node to fetch the
  // scene, this one restarted or another of the host, goes on from its chunks,
  // each checked again. Only a copy the cache could not keep is removed.
  copy_unfinished_ = false;
  fetch_.reset();
  const bool connected = connection_open_;
  phase_ = Phase::stopped;
  log(out, exit_code == kExitOk ? spdlog::level::info : spdlog::level::err, reason);
  out.push_back(CancelPings{});
  if (connected) {
    // The master logs why a node leaves: a node that cannot render says so there too.
    if (exit_code != kExitOk) {
      wire::Envelope goodbye;
      goodbye.mutable_goodbye()->set_reason(reason);
      out.push_back(Send{std::move(goodbye)});
    }
    out.push_back(Close{reason, true});
  }
  out.push_back(Stop{exit_code});
}

// ---------------------------------------------------------------- connection

Actions NodeProtocol::connected(clock::Nanos, std::vector<std::uint8_t> nonce) {
  Actions out;
  if (phase_ == Phase::stopped) return out;
  phase_ = Phase::awaiting_challenge;
  connection_open_ = true;
  nonce_ = std::move(nonce);
  out.push_back(SetDeadline{kHandshakeTimeout, "no welcome from the master within 5 s"});
  return out;
}

Actions NodeProtocol::connect_failed(const std::string& reason, clock::Nanos now) {
  Actions out;
  if (phase_ == Phase::stopped) return out;
  ++attempts_;
  if (!unreachable_since_) unreachable_since_ = now;
  const auto waited = milliseconds((now - *unreachable_since_) / clock::kNanosPerMilli);
  if (waited >= settings_.give_up_after) {
    stop(kExitNoMaster,
         "gave up: the master at " + settings_.master + " was not reachable for " + std::to_string(waited.count()) +
             " ms (" + reason + ")",
         out);
    return out;
  }
  // One line at the first failure and then about every few seconds, not one per try.
  if (attempts_ == 1 || attempts_ % 5 == 0) {
    log(out, spdlog::level::info,
        fmt::format("master at {} not reachable ({}); retrying every {} ms, giving up after {} ms", settings_.master,
                    reason, backoff_.count(), settings_.give_up_after.count()));
  }
  // The last try falls on the limit, not a whole backoff past it.
  out.push_back(Reconnect{std::min(backoff_, settings_.give_up_after - waited)});
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  return out;
}

Actions NodeProtocol::closed(const std::string& reason, clock::Nanos now) {
  Actions out;
  connection_open_ = false;
  out.push_back(CancelPings{});
  if (phase_ == Phase::stopped) return out;
  const bool was_joined = phase_ == Phase::joined;
  fetch_.reset();  // its copy is kept: the fetch goes on from it after the reconnect
  waiting_.reset();
  // The next welcome names every asset again.
  target_.reset();
  offers_.clear();
  readying_.reset();
  phase_ = Phase::disconnected;
  pending_.reset();
  held_.clear();
  round_open_ = false;
  ping_owed_ = false;
  last_begin_.reset();
  if (was_joined) {
    log(out, spdlog::level::warn,
        "lost the master: " + reason + "; " + (settings_.hold_last_frame ? "holding the last frame" : "showing black") +
            " while reconnecting");
    if (!settings_.hold_last_frame) out.push_back(ShowBlack{});
  } else {
    log(out, spdlog::level::info, "connection to the master closed during the handshake: " + reason);
  }
  Actions retry = connect_failed(reason, now);
  out.insert(out.end(), std::make_move_iterator(retry.begin()), std::make_move_iterator(retry.end()));
  return out;
}

Actions NodeProtocol::interrupted(const std::string& signal_name) {
  Actions out;
  if (connection_open_ && phase_ != Phase::stopped) {
    wire::Envelope goodbye;
    goodbye.mutable_goodbye()->set_reason("node " + signal_name);
    out.push_back(Send{std::move(goodbye)});
  }
  stop(kExitOk, "stopping on " + signal_name, out);
  return out;
}

// ---------------------------------------------------------------- messages

// An asset's chunks come while frames go on, to a fetch of one.
bool NodeProtocol::accepts(const wire::Envelope& message) const {
  if (message.body_case() == wire::Envelope::kSceneChunk && phase_ == Phase::joined) return fetch_.has_value();
  return accepts(phase_, message.body_case());
}

// Which messages each phase takes; a Challenge, a Refuse and a Goodbye are taken
// in every phase, before the version is checked (message()).
bool NodeProtocol::accepts(Phase phase, wire::Envelope::BodyCase kind) {
  switch (kind) {
    case wire::Envelope::kWelcome:
      return phase == Phase::awaiting_welcome;
    case wire::Envelope::kSceneChunk:
      return phase == Phase::fetching_scene;
    case wire::Envelope::kAssetOffer:
      return phase == Phase::preparing_scene || phase == Phase::fetching_scene || phase == Phase::configuring ||
             phase == Phase::awaiting_state || phase == Phase::joined;
    case wire::Envelope::kHeartbeat:
      return phase == Phase::preparing_scene || phase == Phase::fetching_scene || phase == Phase::joined;
    case wire::Envelope::kResync:
      return phase == Phase::awaiting_state || phase == Phase::joined;
    case wire::Envelope::kFrameBegin:
    case wire::Envelope::kStagedEdit:
    case wire::Envelope::kSwap:
    case wire::Envelope::kPong:
      return phase == Phase::joined;
    default:
      return false;
  }
}

Actions NodeProtocol::message(const wire::Envelope& message, clock::Nanos now) {
  Actions out;
  if (phase_ == Phase::stopped || !connection_open_) return out;
  switch (message.body_case()) {
    case wire::Envelope::kChallenge:
      on_challenge(message, out);
      return out;
    case wire::Envelope::kRefuse:
      if (message.refuse().retriable()) {
        log(out, spdlog::level::warn, "the master refused this node for now: " + message.refuse().reason());
        out.push_back(Close{"refused (will retry)"});
      } else {
        stop(kExitRefused, "the master refused this node: " + message.refuse().reason(), out);
      }
      return out;
    case wire::Envelope::kGoodbye:
      stop(kExitOk, "the master said goodbye (" + message.goodbye().reason() + ")", out);
      return out;
    default:
      break;
  }
  if (message.protocol_version() != net::kProtocolVersion) {
    stop(kExitRefused,
         "the master speaks protocol v" + std::to_string(message.protocol_version()) + ", this node v" +
             std::to_string(net::kProtocolVersion),
         out);
    return out;
  }
  if (!accepts(message)) {
    out.push_back(Close{std::string("unexpected ") + net::body_name(message) +
                        (phase_ == Phase::joined ? " from the master" : " before the welcome")});
    return out;
  }
  switch (message.body_case()) {
    case wire::Envelope::kWelcome:
      on_welcome(message.welcome(), out);
      break;
    case wire::Envelope::kSceneChunk:
      on_scene_chunk(message.scene_chunk(), out);
      break;
    case wire::Envelope::kAssetOffer:
      on_asset_offer(message.asset_offer(), out);
      break;
    case wire::Envelope::kStagedEdit:
      // The state changes, nothing is drawn: a frame waiting for its deadline
      // has its images already. Only what is held for it comes first.
      if (held_.empty()) {
        on_staged_edit(message.staged_edit(), out);
      } else {
        held_.push_back(message);
      }
      break;
    case wire::Envelope::kResync:
    case wire::Envelope::kFrameBegin:
    case wire::Envelope::kSwap:
      // A frame is waiting for its deadline: nothing may touch it (a new state,
      // the next frame drawn over it) before it is shown.
      if (pending_) {
        held_.push_back(message);
      } else if (message.has_resync()) {
        on_resync(message.resync(), now, out);
      } else if (message.has_frame_begin()) {
        on_frame_begin(message.frame_begin(), now, out);
      } else {
        on_swap(message.swap(), now, out);
      }
      break;
    case wire::Envelope::kPong:
      on_pong(message.pong(), now, out);
      break;
    default:  // a heartbeat: the connection is alive, which it already knows
      break;
  }
  return out;
}

Actions NodeProtocol::answer(Answer answer, clock::Nanos now) {
  Actions out;
  std::visit(util::Overloaded{
                 [&](const Configured& a) { on_configured(a, out); },
                 [&](const SceneFound& a) { on_scene_found(a, out); },
                 [&](const SceneFetchedElsewhere& a) { on_scene_fetched_elsewhere(a, now, out); },
                 [&](const SceneCopyStarted& a) { on_scene_copy_started(a, now, out); },
                 [&](const SceneStoreFailed& a) { on_scene_store_failed(a, out); },
                 [&](const SceneCopyFinished& a) { on_scene_copy_finished(a, now, out); },
                 [&](const FrameRendered& a) { on_rendered(a, out); },
                 [&](const ImagePresented&) { on_presented(now, out); },
                 [&](const AssetLoaded& a) { on_asset_loaded(a, out); },
             },
             answer);
  return out;
}

Actions NodeProtocol::due(Due timer, clock::Nanos now) {
  Actions out;
  switch (timer) {
    case Due::ping:
      on_ping_due(now, out);
      break;
    case Due::present:
      on_present_due(now, out);
      break;
    case Due::scene_recheck:
      on_scene_recheck_due(out);
      break;
  }
  return out;
}

void NodeProtocol::on_challenge(const wire::Envelope& message, Actions& out) {
  if (phase_ != Phase::awaiting_challenge) {
    out.push_back(Close{"a second challenge from the master"});
    return;
  }
  const wire::Challenge& challenge = message.challenge();
  if (challenge.secret_required() && !settings_.secret) {
    stop(kExitRefused,
         "the master requires the installation's shared secret: start this node with --secret-file FILE (the file "
         "the config's master.secret_file names)",
         out);
    return;
  }
  if (settings_.secret && !challenge.secret_required()) {
    // A master without the secret could be anyone: it would be given this
    // projector and its scene would be cached here.
    stop(kExitRefused,
         "the master at " + settings_.master +
             " asked for no secret, but this node has one (--secret-file): it is not this installation's master, or "
             "it runs without master.secret_file; not joining it",
         out);
    return;
  }
  if (settings_.secret && (challenge.nonce().size() != net::kNonceBytes || nonce_.size() != net::kNonceBytes)) {
    stop(kExitRefused,
         fmt::format("cannot authenticate: the master's challenge has {} random bytes and this node {}, not {}",
                     challenge.nonce().size(), nonce_.size(), net::kNonceBytes),
         out);
    return;
  }
  wire::Envelope hello;
  hello.set_protocol_version(settings_.faults.protocol_version);
  hello.mutable_hello()->set_node_id(settings_.id);
  hello.mutable_hello()->add_capabilities("render");
  std::optional<net::SessionKeys> keys;
  if (settings_.secret) {
    const std::string& theirs = challenge.nonce();
    keys = net::prove_hello(*settings_.secret,
                            std::span(reinterpret_cast<const std::uint8_t*>(theirs.data()), theirs.size()), nonce_,
                            settings_.faults.protocol_version, *hello.mutable_hello());
  }
  out.push_back(Send{std::move(hello)});
  if (keys) out.push_back(Protect{keys->to_master, keys->to_node});
  phase_ = Phase::awaiting_welcome;
}

void NodeProtocol::on_welcome(const wire::Welcome& welcome, Actions& out) {
  auto job = protocol::decode_welcome(welcome, settings_.id);
  if (!job) {
    stop(kExitRefused, "the master's welcome cannot be used: " + job.error(), out);
    return;
  }
  job_ = std::move(job).value();
  target_.reset();
  prepare_next(out);
}

void NodeProtocol::configure(Actions& out) {
  phase_ = Phase::configuring;
  out.push_back(Configure{*job_});
}

void NodeProtocol::on_configured(const Configured& answer, Actions& out) {
  const WarmUp& warm_up = answer.warm_up;
  if (phase_ != Phase::configuring) return;  // the connection went meanwhile
  if (!answer.result) {
    stop(kExitRefused, "cannot drive projector '" + settings_.id + "': " + answer.result.error(), out);
    return;
  }
  frame_period_ = job_->frame_period;
  images_ = job_->job.self().color_fields.images;
  heartbeat_ = std::max(job_->heartbeat, milliseconds(10));
  liveness_timeout_ = job_->liveness_timeout;
  wire::Envelope envelope;
  envelope.mutable_configured()->set_renderer(answer.renderer);
  envelope.mutable_configured()->set_warm_up_ns(warm_up.frame);
  envelope.mutable_configured()->set_capture_ns(warm_up.capture);
  out.push_back(Send{std::move(envelope)});
  phase_ = Phase::awaiting_state;
  out.push_back(SetDeadline{kHandshakeTimeout, "no state from the master within 5 s of being configured"});
  const config::Projector& p = job_->job.self();
  // What it draws besides a frame per frame period, said where an operator looks first.
  std::string drawing;
  for (const std::string& part : {config::describe(p.color_fields), config::describe(p.up_conversion)}) {
    if (!part.empty()) drawing += "; " + part;
  }
  log(out, spdlog::level::info,
      fmt::format(
          "driving '{}': {}×{} px on screen '{}', eye {}, frame period {:.3f} ms; {}{}{}", p.id, p.width, p.height,
          job_->job.screen().id, config::to_string(p.eye), static_cast<double>(frame_period_) / 1e6, answer.renderer,
          warm_up.frame > 0 ? fmt::format("; warm-up frame {:.1f} ms{}", static_cast<double>(warm_up.frame) / 1e6,
                                          warm_up.capture > 0 ? fmt::format(", {:.1f} ms more when captured",
                                                                            static_cast<double>(warm_up.capture) / 1e6)
                                                              : "")
                            : "",
          drawing));
}

void NodeProtocol::on_resync(const wire::Resync& resync, clock::Nanos now, Actions& out) {
  auto state = scene::from_snapshot(resync.snapshot());
  if (!state) {
    out.push_back(Close{"bad snapshot from the master: " + state.error()});
    return;
  }
  const scene::InstancesHash instances = scene::instances_hash(state.value());
  if (scene::state_hash(state.value(), instances) != resync.state_hash()) {
    out.push_back(Close{"the master's snapshot does not match its hash"});
    return;
  }
  state_ = std::move(state).value();
  instances_hash_ = instances;
  past_frames_.clear();
  next_frame_ = resync.next_frame_id();
  if (phase_ == Phase::joined) {
    // A repair between frames: the frame already rendered still swaps.
    log(out, spdlog::level::info, "state resynchronized at frame " + std::to_string(next_frame_));
    return;
  }
  rendered_any_ = false;
  phase_ = Phase::joined;
  estimator_ = clock::OffsetEstimator{};  // samples from an earlier connection may be from another master
  unreachable_since_.reset();
  attempts_ = 0;
  backoff_ = kFirstBackoff;
  out.push_back(CancelDeadline{});
  out.push_back(
      SetLiveness{liveness_timeout_, "master silent for " + std::to_string(liveness_timeout_.count()) + " ms"});
  log(out, spdlog::level::info, "joined at frame " + std::to_string(next_frame_));
  // A quick burst of pings to get a clock offset before the first swap.
  pings_in_burst_ = kPingBurst;
  send_ping(now, out);
  ready_next(out);  // assets offered while this node set up
}

// The instances as the next frame will show them, staged between rounds: the
// FrameBegin that follows carries only what changed since.
void NodeProtocol::on_staged_edit(const wire::StagedEdit& staged, Actions& out) {
  if (staged.frame_id() != next_frame_) {
    log(out, spdlog::level::warn,
        fmt::format("an edit staged for frame {} came while frame {} is next", staged.frame_id(), next_frame_));
  }
  if (auto applied = scene::apply_delta(state_, staged.delta(), instances_hash_); !applied) {
    out.push_back(
        Close{"cannot apply the edit staged for frame " + std::to_string(staged.frame_id()) + ": " + applied.error()});
  }
}

void NodeProtocol::on_frame_begin(const wire::FrameBegin& begin, clock::Nanos now, Actions& out) {
  last_begin_ = now;
  // A frame to skip has no round: no swap comes for it.
  round_open_ = !begin.skip();
  if (begin.frame_id() != next_frame_) {
    log(out, spdlog::level::warn,
        "frame ids jumped from " + std::to_string(next_frame_) + " to " + std::to_string(begin.frame_id()));
  }
  next_frame_ = begin.frame_id() + 1;
  if (auto applied = scene::apply_delta(state_, begin.delta(), instances_hash_); !applied) {
    out.push_back(Close{"cannot apply frame " + std::to_string(begin.frame_id()) + ": " + applied.error()});
    return;
  }
  if (settings_.faults.corrupt_state_at_frame != 0 && begin.frame_id() == settings_.faults.corrupt_state_at_frame) {
    state_.eye_now.x += 1e-3;
  }
  last_hash_ = scene::state_hash(state_, instances_hash_);
  if (last_hash_ != begin.state_hash()) {
    log(out, spdlog::level::warn,
        fmt::format("state hash {:016x} differs from the master's {:016x} at frame {}", last_hash_, begin.state_hash(),
                    begin.frame_id()));
  }
  auto decoded = protocol::decode_frame_begin(begin, job_ ? job_->light_count : 0);
  if (!decoded) {
    out.push_back(Close{decoded.error()});
    return;
  }
  protocol::FrameMessage frame = std::move(decoded).value();
  // A node that lags shows an older frame's content (the light share and the
  // scene sent ahead apply at once: they are how this node draws, not content).
  const protocol::FrameMessage* shown = &frame;
  const scene::SceneState* shown_state = &state_;
  if (settings_.faults.lag_frames > 0) {
    protocol::FrameMessage kept = frame;
    kept.lights.reset();
    kept.ahead.reset();
    past_frames_.push_back({std::move(kept), state_});
    while (past_frames_.size() > settings_.faults.lag_frames + 1) past_frames_.pop_front();
    shown = &past_frames_.front().frame;
    shown_state = &past_frames_.front().state;
  }
  FrameInput input;
  input.frame_id = frame.frame_id;
  input.simulation_time = shown->simulation_time;
  input.present_time = shown->present_time;
  input.frame_period = frame_period_;
  input.state = shown_state;
  input.capture = frame.capture;
  input.focus = shown->focus;
  share_ = std::move(frame.lights);
  if (share_) input.lights = &*share_;
  ahead_ = std::move(frame.ahead);
  if (ahead_) {
    input.ahead = &*ahead_;
    input.ahead_frame = frame.ahead_frame;
  }
  if (frame.skip) {
    ++skipped_;
    if (!skipping_) {
      skipping_ = true;
      log(out, spdlog::level::warn,
          fmt::format("behind: skipping frames from frame {} (the master no longer waits for this node); drawing the "
                      "newest once the frame being drawn is done",
                      frame.frame_id));
    }
    out.push_back(Skip{input});
    return;
  }
  if (skipping_) {
    skipping_ = false;
    log(out, spdlog::level::info,
        fmt::format("caught up: drawing frame {} after skipping {} frame(s)", frame.frame_id, skipped_));
    skipped_ = 0;
  }
  last_content_frame_ = shown->frame_id;
  rendering_ = input;
  out.push_back(Render{input});
}

namespace {

wire::DrawnAs drawn_as(const Rendered& how) {
  switch (how.kind) {
    case up::FrameKind::full:
      return wire::DRAWN_FULL;
    case up::FrameKind::key:
      return wire::DRAWN_KEY;
    case up::FrameKind::between:
      return how.key_ahead ? wire::DRAWN_BETWEEN_AND_KEY_AHEAD : wire::DRAWN_BETWEEN;
    case up::FrameKind::shown:
      return wire::DRAWN_KEY_SHOWN;
  }
  return wire::DRAWN_FULL;
}

}  // namespace

void NodeProtocol::on_rendered(const FrameRendered& answer, Actions& out) {
  const std::uint64_t frame_id = answer.frame_id;
  if (!rendering_ || rendering_->frame_id != frame_id) return;
  rendering_.reset();
  last_rendered_ = frame_id;
  rendered_any_ = true;
  if (phase_ != Phase::joined || !connection_open_) return;
  wire::Envelope envelope;
  auto& ready = *envelope.mutable_frame_ready();
  ready.set_frame_id(frame_id);
  ready.set_render_ns(answer.render_time);
  ready.set_state_hash(last_hash_);
  ready.set_drawn_as(drawn_as(answer.how));
  out.push_back(Send{std::move(envelope)});
}

}  // namespace optique::node
