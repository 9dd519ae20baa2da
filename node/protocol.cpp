#include "node/protocol.h"

#include <fmt/format.h>

#include <algorithm>

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
  if (phase_ == Phase::awaiting_welcome && message.body_case() == wire::Envelope::kWelcome) {
    on_welcome(message.welcome(), out);
    return out;
  }
  if (phase_ == Phase::fetching_scene && message.body_case() == wire::Envelope::kSceneChunk) {
    on_scene_chunk(message.scene_chunk(), out);
    return out;
  }
  if ((phase_ == Phase::preparing_scene || phase_ == Phase::fetching_scene) &&
      message.body_case() == wire::Envelope::kHeartbeat) {
    return out;
  }
  if ((phase_ == Phase::awaiting_state || phase_ == Phase::joined) && message.body_case() == wire::Envelope::kResync) {
    if (pending_) {
      held_.push_back(message);  // after the frame waiting to be shown
    } else {
      on_resync(message.resync(), now, out);
    }
    return out;
  }
  if (phase_ != Phase::joined) {
    out.push_back(Close{std::string("unexpected ") + net::body_name(message) + " before the welcome"});
    return out;
  }
  switch (message.body_case()) {
    case wire::Envelope::kFrameBegin:
      // A frame is waiting for its deadline: the next one must not be drawn over
      // it before it is shown.
      if (pending_) {
        held_.push_back(message);
      } else {
        on_frame_begin(message.frame_begin(), now, out);
      }
      break;
    case wire::Envelope::kSwap:
      if (pending_) {
        held_.push_back(message);
      } else {
        on_swap(message.swap(), now, out);
      }
      break;
    case wire::Envelope::kPong:
      on_pong(message.pong(), now, out);
      break;
    case wire::Envelope::kHeartbeat:
      break;
    default:
      out.push_back(Close{std::string("unexpected ") + net::body_name(message) + " from the master"});
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
  hello.set_protocol_version(settings_.protocol_version);
  hello.mutable_hello()->set_node_id(settings_.id);
  hello.mutable_hello()->add_capabilities("render");
  std::optional<net::SessionKeys> keys;
  if (settings_.secret) {
    const std::string& theirs = challenge.nonce();
    std::vector<std::uint8_t> both(theirs.begin(), theirs.end());
    both.insert(both.end(), nonce_.begin(), nonce_.end());
    const auto mac = net::hello_mac(*settings_.secret, both, settings_.id, settings_.protocol_version);
    hello.mutable_hello()->set_nonce_mac(mac.data(), mac.size());
    hello.mutable_hello()->set_node_nonce(nonce_.data(), nonce_.size());
    keys = net::derive_session_keys(*settings_.secret, std::span(both).first(net::kNonceBytes), nonce_, settings_.id,
                                    settings_.protocol_version);
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
  if (!settings_.needs_scene_files || job_->scene_files.files.empty()) {
    configure(out);
    return;
  }
  const std::uint64_t bytes = job_->scene_files.total_bytes();
  if (bytes > settings_.most_scene_bytes) {
    stop(kExitRefused,
         fmt::format("the master's scene {} is {:.1f} MiB, more than the {:.1f} MiB this node takes "
                     "(--max-scene-mb)",
                     job_->job.installation.scene.gltf, static_cast<double>(bytes) / (1 << 20),
                     static_cast<double>(settings_.most_scene_bytes) / (1 << 20)),
         out);
    return;
  }
  phase_ = Phase::preparing_scene;
  out.push_back(PrepareScene{job_->scene_files, job_->scene_sha256});
}

void NodeProtocol::configure(Actions& out) {
  phase_ = Phase::configuring;
  out.push_back(Configure{*job_});
}

// The cache cannot hold the scene (no room, no permission): not something a
// retry cures.
void NodeProtocol::cache_failed(const std::string& error, Actions& out) {
  if (copy_unfinished_) out.push_back(AbandonScene{});
  stop(kExitRefused, "cannot keep the master's scene here: " + error, out);
}

Actions NodeProtocol::scene_found(const std::string& gltf_path) {
  Actions out;
  if (phase_ != Phase::preparing_scene) return out;
  job_->scene_path = gltf_path;
  log(out, spdlog::level::info,
      "the scene " + job_->scene_sha256.substr(0, 12) + "… is here: " + gltf_path +
          (waiting_ ? ", fetched by another node of this host" : ""));
  waiting_.reset();
  configure(out);
  return out;
}

Actions NodeProtocol::scene_fetched_elsewhere(std::uint64_t bytes_there, clock::Nanos now) {
  Actions out;
  if (phase_ != Phase::preparing_scene) return out;
  const std::uint64_t total = job_->scene_files.total_bytes();
  bytes_there = std::min(bytes_there, total);
  const auto mib = [](std::uint64_t bytes) { return static_cast<double>(bytes) / (1 << 20); };
  if (!waiting_) {
    waiting_ = SceneWaiting{now, now, std::nullopt, bytes_there};
    log(out, spdlog::level::info,
        fmt::format("another node of this host is fetching the scene {} into this cache ({:.1f} of {:.1f} MiB "
                    "there): waiting for its copy",
                    job_->job.installation.scene.gltf, mib(bytes_there), mib(total)));
  } else if (bytes_there > waiting_->bytes) {
    waiting_->bytes = bytes_there;
    waiting_->grew_at = now;
  }
  if (now - waiting_->grew_at >= kSceneStall.count() * clock::kNanosPerMilli) {
    log(out, spdlog::level::warn,
        fmt::format("the copy of the scene another node of this host is fetching has not grown for {} s "
                    "({:.1f} of {:.1f} MiB there): fetching the scene from the master",
                    kSceneStall.count() / 1000, mib(waiting_->bytes), mib(total)));
    waiting_.reset();
    out.push_back(PrepareScene{job_->scene_files, job_->scene_sha256, false});
    return out;
  }
  if (!waiting_->told_at || now - *waiting_->told_at >= kSceneWaitWord.count() * clock::kNanosPerMilli) {
    waiting_->told_at = now;
    wire::Envelope wait;
    wait.mutable_scene_wait()->set_scene_sha256(job_->scene_sha256);
    wait.mutable_scene_wait()->set_bytes_there(waiting_->bytes);
    out.push_back(Send{std::move(wait)});
  }
  // Past the stall, in case the cache stops answering: the connection goes.
  out.push_back(SetDeadline{kSceneStall + 2 * kSceneWaitWord,
                            "waited " + std::to_string((kSceneStall + 2 * kSceneWaitWord).count() / 1000) +
                                " s for another node's copy of the scene"});
  out.push_back(RecheckScene{kSceneRecheck});
  return out;
}

Actions NodeProtocol::scene_recheck_due(clock::Nanos) {
  Actions out;
  if (phase_ != Phase::preparing_scene || !waiting_) return out;
  out.push_back(PrepareScene{job_->scene_files, job_->scene_sha256});
  return out;
}

Actions NodeProtocol::scene_copy_started(const Result<protocol::SceneFetch::Present>& started, clock::Nanos now) {
  Actions out;
  if (phase_ != Phase::preparing_scene) return out;
  if (!started) {
    cache_failed(started.error(), out);
    return out;
  }
  copy_unfinished_ = true;
  waiting_.reset();
  fetch_.emplace(job_->scene_files, job_->scene_sha256, started.value());
  fetch_started_ = now;
  fetch_had_bytes_ = fetch_->bytes_stored();
  fetch_quarters_logged_ = 0;
  phase_ = Phase::fetching_scene;
  const double total = static_cast<double>(job_->scene_files.total_bytes()) / (1 << 20);
  log(out, spdlog::level::info,
      fetch_->bytes_stored() == 0
          ? fmt::format("fetching the scene {} from the master: {} file(s), {:.1f} MiB",
                        job_->job.installation.scene.gltf, job_->scene_files.files.size(), total)
          : fmt::format("fetching the rest of the scene {} from the master: {:.1f} of {:.1f} MiB were here already",
                        job_->job.installation.scene.gltf, static_cast<double>(fetch_->bytes_stored()) / (1 << 20),
                        total));
  out.push_back(SetDeadline{
      kSceneStall, "no part of the scene from the master for " + std::to_string(kSceneStall.count() / 1000) + " s"});
  for (wire::Envelope& request : fetch_->requests()) out.push_back(Send{std::move(request)});
  if (fetch_->done()) out.push_back(FinishScene{});  // only empty files
  return out;
}

void NodeProtocol::on_scene_chunk(const wire::SceneChunk& chunk, Actions& out) {
  const protocol::SceneFetch::Verdict verdict = fetch_->take(chunk);
  switch (verdict.kind) {
    case protocol::SceneFetch::Verdict::Kind::fail:
      out.push_back(Close{"the scene from the master: " + verdict.problem});
      return;
    case protocol::SceneFetch::Verdict::Kind::ask_again:
      log(out, spdlog::level::warn, "the scene from the master: " + verdict.problem + "; asking for it again");
      break;
    case protocol::SceneFetch::Verdict::Kind::store:
      out.push_back(StoreSceneChunk{verdict.file, verdict.offset, chunk.data()});
      break;
  }
  out.push_back(SetDeadline{
      kSceneStall, "no part of the scene from the master for " + std::to_string(kSceneStall.count() / 1000) + " s"});
  const std::uint64_t total = fetch_->manifest().total_bytes();
  const int quarters = total == 0 ? 4 : static_cast<int>(4 * fetch_->bytes_stored() / total);
  if (quarters > fetch_quarters_logged_ && quarters < 4 && total >= protocol::kSceneProgressBytes) {
    fetch_quarters_logged_ = quarters;
    log(out, spdlog::level::info, fmt::format("fetching the scene: {} %", 25 * quarters));
  }
  if (fetch_->done()) {
    out.push_back(FinishScene{});
    return;
  }
  for (wire::Envelope& request : fetch_->requests()) out.push_back(Send{std::move(request)});
}

Actions NodeProtocol::scene_store_failed(const std::string& error) {
  Actions out;
  if (phase_ != Phase::fetching_scene) return out;
  cache_failed(error, out);
  return out;
}

Actions NodeProtocol::scene_copy_finished(const Result<std::string>& gltf_path, clock::Nanos now) {
  Actions out;
  if (phase_ != Phase::fetching_scene) return out;
  if (!gltf_path) {
    cache_failed(gltf_path.error(), out);
    return out;
  }
  copy_unfinished_ = false;
  // From the first request to the copy in place.
  log(out, spdlog::level::info,
      fmt::format("fetched the scene: {}{}",
                  protocol::transfer_text(fetch_->manifest().total_bytes() - fetch_had_bytes_, now - fetch_started_),
                  fetch_->chunks_asked_again() > 0
                      ? fmt::format(", {} chunk(s) asked for again", fetch_->chunks_asked_again())
                      : ""));
  fetch_.reset();
  job_->scene_path = gltf_path.value();
  configure(out);
  return out;
}

Actions NodeProtocol::configured(const Result<void>& result, const std::string& renderer_description,
                                 WarmUp warm_up) {
  Actions out;
  if (phase_ != Phase::configuring) return out;  // the connection went meanwhile
  if (!result) {
    stop(kExitRefused, "cannot drive projector '" + settings_.id + "': " + result.error(), out);
    return out;
  }
  frame_period_ = job_->frame_period;
  images_ = job_->job.self().color_fields.images;
  heartbeat_ = std::max(job_->heartbeat, milliseconds(10));
  liveness_timeout_ = job_->liveness_timeout;
  wire::Envelope envelope;
  envelope.mutable_configured()->set_renderer(renderer_description);
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
      fmt::format("driving '{}': {}×{} px on screen '{}', eye {}, frame period {:.3f} ms; {}{}{}", p.id, p.width,
                  p.height, job_->job.screen().id, config::to_string(p.eye), static_cast<double>(frame_period_) / 1e6,
                  renderer_description,
                  warm_up.frame > 0 ? fmt::format("; warm-up frame {:.1f} ms{}", static_cast<double>(warm_up.frame) / 1e6,
                                                  warm_up.capture > 0
                                                      ? fmt::format(", {:.1f} ms more when captured",
                                                                    static_cast<double>(warm_up.capture) / 1e6)
                                                      : "")
                                    : "",
                  drawing));
  return out;
}

void NodeProtocol::on_resync(const wire::Resync& resync, clock::Nanos now, Actions& out) {
  auto state = scene::from_snapshot(resync.snapshot());
  if (!state) {
    out.push_back(Close{"bad snapshot from the master: " + state.error()});
    return;
  }
  if (scene::state_hash(state.value()) != resync.state_hash()) {
    out.push_back(Close{"the master's snapshot does not match its hash"});
    return;
  }
  state_ = std::move(state).value();
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
  if (auto applied = scene::apply_delta(state_, begin.delta()); !applied) {
    out.push_back(Close{"cannot apply frame " + std::to_string(begin.frame_id()) + ": " + applied.error()});
    return;
  }
  if (settings_.corrupt_state_at_frame != 0 && begin.frame_id() == settings_.corrupt_state_at_frame) {
    state_.eye_now.x += 1e-3;
  }
  last_hash_ = scene::state_hash(state_);
  if (last_hash_ != begin.state_hash()) {
    log(out, spdlog::level::warn,
        fmt::format("state hash {:016x} differs from the master's {:016x} at frame {}", last_hash_, begin.state_hash(),
                    begin.frame_id()));
  }
  // A node that lags shows an older frame's content (the light share applies at
  // once: it is how this node's light is split, not content).
  const wire::FrameBegin* shown = &begin;
  const scene::SceneState* shown_state = &state_;
  if (settings_.lag_frames > 0) {
    past_frames_.push_back({begin, state_});
    while (past_frames_.size() > settings_.lag_frames + 1) past_frames_.pop_front();
    shown = &past_frames_.front().begin;
    shown_state = &past_frames_.front().state;
  }
  FrameInput input;
  input.frame_id = begin.frame_id();
  input.simulation_time = shown->simulation_time_ns();
  input.present_time = shown->present_time_ns();
  input.frame_period = frame_period_;
  input.state = shown_state;
  input.capture = begin.capture();
  if (shown->has_focus()) {
    auto focus = protocol::decode_focus(shown->focus());
    if (!focus) {
      out.push_back(Close{"frame " + std::to_string(begin.frame_id()) + ": " + focus.error()});
      return;
    }
    input.focus = focus.value();
  }
  share_.reset();
  if (begin.has_lights()) {
    auto share = protocol::decode_light_share(begin.lights(), job_ ? job_->light_count : 0);
    if (!share) {
      out.push_back(Close{"frame " + std::to_string(begin.frame_id()) + ": lights: " + share.error()});
      return;
    }
    share_ = std::move(share).value();
    input.lights = &*share_;
  }
  ahead_.reset();
  if (begin.has_ahead()) {
    const std::uint64_t on = begin.ahead_frame() - begin.frame_id();
    if (begin.ahead_frame() <= begin.frame_id() || on > static_cast<std::uint64_t>(config::kMostFramesAhead)) {
      out.push_back(Close{"frame " + std::to_string(begin.frame_id()) + ": the scene sent ahead is for frame " +
                          std::to_string(begin.ahead_frame()) + ", not 1…" + std::to_string(config::kMostFramesAhead) +
                          " frames on"});
      return;
    }
    auto ahead = scene::from_snapshot(begin.ahead());
    if (!ahead) {
      out.push_back(Close{"frame " + std::to_string(begin.frame_id()) + ": the scene sent ahead: " + ahead.error()});
      return;
    }
    ahead_ = std::move(ahead).value();
    input.ahead = &*ahead_;
    input.ahead_frame = begin.ahead_frame();
  }
  if (begin.skip()) {
    ++skipped_;
    if (!skipping_) {
      skipping_ = true;
      log(out, spdlog::level::warn,
          fmt::format("behind: skipping frames from frame {} (the master no longer waits for this node); drawing the "
                      "newest once the frame being drawn is done",
                      begin.frame_id()));
    }
    out.push_back(Skip{input});
    return;
  }
  if (skipping_) {
    skipping_ = false;
    log(out, spdlog::level::info,
        fmt::format("caught up: drawing frame {} after skipping {} frame(s)", begin.frame_id(), skipped_));
    skipped_ = 0;
  }
  last_content_frame_ = shown->frame_id();
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

Actions NodeProtocol::rendered(std::uint64_t frame_id, clock::Nanos render_time, const Rendered& how) {
  Actions out;
  if (!rendering_ || rendering_->frame_id != frame_id) return out;
  rendering_.reset();
  last_rendered_ = frame_id;
  rendered_any_ = true;
  if (phase_ != Phase::joined || !connection_open_) return out;
  wire::Envelope envelope;
  auto& ready = *envelope.mutable_frame_ready();
  ready.set_frame_id(frame_id);
  ready.set_render_ns(render_time);
  ready.set_state_hash(last_hash_);
  ready.set_drawn_as(drawn_as(how));
  out.push_back(Send{std::move(envelope)});
  return out;
}

void NodeProtocol::on_swap(const wire::FrameSwap& swap, clock::Nanos now, Actions& out) {
  if (!rendered_any_ || swap.frame_id() != last_rendered_) {
    log(out, spdlog::level::warn,
        "swap for frame " + std::to_string(swap.frame_id()) + " but the last rendered frame is " +
            std::to_string(last_rendered_) + "; not presenting");
    end_round(now, out);
    return;
  }
  const std::optional<clock::ClockEstimate> estimate = estimator_.at(settings_.clock.to_local(now));
  const clock::Nanos to_master = estimate ? estimate->offset : 0;
  clock::Nanos deadline = settings_.clock.to_monotonic(swap.present_deadline_ns() - to_master);
  // Never wait on a deadline from a broken or hostile master for longer than a
  // few frames.
  const clock::Nanos longest = std::max<clock::Nanos>(4 * frame_period_, 100 * clock::kNanosPerMilli);
  if (deadline > now + longest) {
    log(out, spdlog::level::warn,
        fmt::format("swap for frame {} asks to present {:.1f} ms from now; presenting in {:.1f} ms", swap.frame_id(),
                    static_cast<double>(deadline - now) / 1e6, static_cast<double>(longest) / 1e6));
    deadline = now + longest;
  }
  pending_ = Pending{swap.frame_id(), deadline, swap.present_deadline_ns(), false};
  wait_for_pending(now, out);
}

// Checked when the swap comes and again when the deadline does: a stop can
// stretch the wait too. An image is stale once the next one's time has come.
bool NodeProtocol::stale(clock::Nanos now, Actions& out) const {
  if (now <= pending_->deadline + frame_period_ / images_) return false;
  log(out, spdlog::level::warn,
      fmt::format("frame {}{}'s present deadline passed {:.1f} ms ago: not showing a stale frame", pending_->frame_id,
                  images_ > 1 ? fmt::format(" image {}", pending_->image) : "",
                  static_cast<double>(now - pending_->deadline) / 1e6));
  return true;
}

bool NodeProtocol::next_image() {
  if (pending_->image + 1 >= images_) return false;
  const clock::Nanos later = frame_period_ / images_;
  pending_->image += 1;
  pending_->deadline += later;
  pending_->master_deadline += later;
  pending_->due = false;
  return true;
}

void NodeProtocol::wait_for_pending(clock::Nanos now, Actions& out) {
  do {
    if (!stale(now, out)) {
      out.push_back(PresentAt{pending_->frame_id, pending_->deadline});
      return;
    }
  } while (next_image());
  pending_.reset();
  end_round(now, out);
}

// The frame's next image, its share of the frame later, while what came
// meanwhile waits for it; or, after the last, the frame is over and that goes on.
void NodeProtocol::image_done(clock::Nanos now, Actions& out) {
  if (next_image()) {
    wait_for_pending(now, out);
  } else {
    pending_.reset();
    end_round(now, out);
  }
  if (!pending_) release_held(now, out);
}

Actions NodeProtocol::present_due(clock::Nanos now) {
  Actions out;
  if (!pending_ || pending_->due) return out;
  if (!stale(now, out)) {
    pending_->due = true;
    out.push_back(Present{pending_->image});
    return out;
  }
  image_done(now, out);  // not shown
  return out;
}

// What came while a frame waited for its deadline, in order, until one of them
// waits again.
void NodeProtocol::release_held(clock::Nanos now, Actions& out) {
  while (!held_.empty() && !pending_) {
    wire::Envelope next = std::move(held_.front());
    held_.pop_front();
    Actions more = message(next, now);
    out.insert(out.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
}

Actions NodeProtocol::presented(clock::Nanos now) {
  Actions out;
  if (!pending_ || !pending_->due) return out;
  const Pending shown = *pending_;
  const clock::Nanos local = settings_.clock.to_local(now);
  // The offset drifts while the node waits for the deadline: convert at this instant.
  const std::optional<clock::ClockEstimate> estimate = estimator_.at(local);
  const clock::Nanos offset = estimate ? estimate->offset : 0;
  const clock::Nanos presented_at = local + offset;
  if (connection_open_ && phase_ == Phase::joined) {
    // The frame's first image is what the master's deadline is for, and what
    // it measures sync by: one report per frame.
    if (shown.image == 0) {
      wire::Envelope envelope;
      auto& report = *envelope.mutable_presented();
      report.set_frame_id(shown.frame_id);
      report.set_presented_ns(presented_at);
      report.set_content_frame_id(last_content_frame_);
      report.set_clock_offset_ns(offset);
      if (estimate) {
        report.set_clock_rtt_ns(estimate->round_trip);
        report.set_clock_drift_ppm(estimate->drift_ppm);
        report.set_clock_error_bound_ns(estimate->error_bound);
      }
      if (settings_.clock.skewed()) {
        report.set_clock_truth_known(true);
        report.set_clock_true_error_ns(offset - (now - local));
      }
      out.push_back(Send{std::move(envelope)});
    }
    log(out, spdlog::level::debug,
        fmt::format("presented frame {}{} at master time {} ns ({:+.1f} µs from the deadline)", shown.frame_id,
                    images_ > 1 ? fmt::format(" image {}", shown.image) : "", presented_at,
                    static_cast<double>(presented_at - shown.master_deadline) / 1e3));
  }
  image_done(now, out);
  return out;
}

// ---------------------------------------------------------------- clock

void NodeProtocol::send_ping(clock::Nanos now, Actions& out) {
  ping_owed_ = false;
  if (phase_ != Phase::joined || !connection_open_) return;
  wire::Envelope envelope;
  envelope.mutable_ping()->set_t1(settings_.clock.to_local(now));
  out.push_back(Send{std::move(envelope)});
  if (pings_in_burst_ > 0) --pings_in_burst_;
  out.push_back(PingIn{pings_in_burst_ > 0 ? kBurstInterval : std::min(heartbeat_, kPingInterval)});
}

Actions NodeProtocol::ping_due(clock::Nanos now) {
  Actions out;
  if (!ping_owed_ && pings_in_burst_ == 0 && in_round(now)) {
    ping_owed_ = true;
    out.push_back(PingIn{kPingDeferral});  // in case the round never ends here (no swap comes)
    return out;
  }
  send_ping(now, out);
  return out;
}

bool NodeProtocol::in_round(clock::Nanos now) const {
  if (round_open_) return true;
  if (!last_begin_ || frame_period_ <= 0) return false;
  const clock::Nanos next_begin = *last_begin_ + frame_period_;
  const clock::Nanos guard = std::chrono::nanoseconds(kRoundGuard).count();
  return now >= next_begin - guard && now < next_begin + guard;
}

void NodeProtocol::end_round(clock::Nanos now, Actions& out) {
  round_open_ = false;
  if (ping_owed_) send_ping(now, out);
}

void NodeProtocol::on_pong(const wire::Pong& pong, clock::Nanos now, Actions& out) {
  const clock::PingSample sample{pong.t1(), pong.t2(), pong.t3(), settings_.clock.to_local(now)};
  if (!estimator_.add(sample)) log(out, spdlog::level::debug, "dropped an impossible clock sample");
}

}  // namespace optique::node
