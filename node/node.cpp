#include "node/node.h"

#include <boost/asio/connect.hpp>

#include <csignal>
#include <cstring>
#include <thread>

namespace optique::node {

using std::chrono::milliseconds;

namespace {
constexpr milliseconds kMaxBackoff{2000};
constexpr milliseconds kHandshakeTimeout{5000};
constexpr milliseconds kConnectTimeout{3000};
constexpr int kPingBurst = 8;
constexpr milliseconds kPingInterval{100};
}  // namespace

Node::Node(asio::io_context& io, NodeOptions options, Renderer& renderer, spdlog::logger& log)
    : io_(io),
      options_(std::move(options)),
      renderer_(renderer),
      log_(log),
      resolver_(io),
      retry_timer_(io),
      ping_timer_(io),
      connect_timer_(io),
      signals_(io, SIGINT, SIGTERM) {}

void Node::start() {
  signals_.async_wait([this](const boost::system::error_code& error, int signal) {
    if (!error) on_signal(signal);
  });
  connect();
}

void Node::connect() {
  if (phase_ == Phase::stopped) return;
  ++attempts_;
  resolver_.async_resolve(
      options_.master_host, options_.master_port,
      [this](const boost::system::error_code& error, const asio::ip::tcp::resolver::results_type& endpoints) {
        if (phase_ == Phase::stopped) return;
        if (error) {
          retry_later("cannot resolve " + options_.master_host + ": " + error.message());
          return;
        }
        auto socket = std::make_shared<asio::ip::tcp::socket>(io_);
        connecting_ = socket;
        // A master host that drops connection attempts silently would keep a
        // connect pending for minutes of kernel retries: bound it.
        connect_timer_.expires_after(kConnectTimeout);
        connect_timer_.async_wait([socket](const boost::system::error_code& e) {
          if (!e) {
            boost::system::error_code ignored;
            socket->close(ignored);
          }
        });
        asio::async_connect(
            *socket, endpoints, [this, socket](const boost::system::error_code& e, const asio::ip::tcp::endpoint&) {
              connect_timer_.cancel();
              connecting_.reset();
              if (phase_ == Phase::stopped) return;
              if (e) {
                retry_later(e == asio::error::operation_aborted ? "no answer to the connection attempt" : e.message());
                return;
              }
              on_connected(std::move(*socket));
            });
      });
}

void Node::retry_later(const std::string& reason) {
  const auto now = std::chrono::steady_clock::now();
  if (!unreachable_) {
    unreachable_ = true;
    unreachable_since_ = now;
  }
  const auto waited = std::chrono::duration_cast<milliseconds>(now - unreachable_since_);
  if (waited >= options_.give_up_after) {
    stop(kExitNoMaster, "gave up: the master at " + options_.master_host + ":" + options_.master_port +
                            " was not reachable for " + std::to_string(waited.count()) + " ms (" + reason + ")");
    return;
  }
  // One line at the first failure and then about every few seconds, not one per try.
  if (attempts_ == 1 || attempts_ % 5 == 0) {
    log_.info("master at {}:{} not reachable ({}); retrying every {} ms, giving up after {} ms", options_.master_host,
              options_.master_port, reason, backoff_.count(), options_.give_up_after.count());
  }
  retry_timer_.expires_after(backoff_);
  backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  retry_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) connect();
  });
}

void Node::on_connected(asio::ip::tcp::socket socket) {
  connection_ = net::Connection::create(std::move(socket), net::kDefaultMaxPayloadBytes);
  phase_ = Phase::awaiting_challenge;
  connection_->start({
      [this](wire::Envelope& message) { on_message(message); },
      [this](const std::string& reason) { on_closed(reason); },
  });
  connection_->set_deadline(kHandshakeTimeout, "no welcome from the master within 5 s");
  log_.debug("connected to the master at {}", connection_->peer());
}

void Node::on_message(wire::Envelope& message) {
  switch (message.body_case()) {
    case wire::Envelope::kChallenge:
      handle_challenge(message);
      return;
    case wire::Envelope::kRefuse:
      if (message.refuse().retriable()) {
        log_.warn("the master refused this node for now: {}", message.refuse().reason());
        connection_->close("refused (will retry)");
      } else {
        stop(kExitRefused, "the master refused this node: " + message.refuse().reason());
      }
      return;
    case wire::Envelope::kGoodbye:
      stop(kExitOk, "the master said goodbye (" + message.goodbye().reason() + ")");
      return;
    default:
      break;
  }
  if (message.protocol_version() != net::kProtocolVersion) {
    stop(kExitRefused, "the master speaks protocol v" + std::to_string(message.protocol_version()) + ", this node v" +
                           std::to_string(net::kProtocolVersion));
    return;
  }
  if (phase_ == Phase::awaiting_welcome && message.body_case() == wire::Envelope::kWelcome) {
    handle_welcome(message.welcome());
    return;
  }
  if ((phase_ == Phase::awaiting_state || phase_ == Phase::joined) && message.body_case() == wire::Envelope::kResync) {
    handle_resync(message.resync());
    return;
  }
  if (phase_ != Phase::joined) {
    connection_->close(std::string("unexpected ") + net::body_name(message) + " before the welcome");
    return;
  }
  switch (message.body_case()) {
    case wire::Envelope::kFrameBegin:
      handle_frame_begin(message.frame_begin());
      break;
    case wire::Envelope::kSwap:
      handle_swap(message.swap());
      break;
    case wire::Envelope::kPong:
      handle_pong(message.pong());
      break;
    case wire::Envelope::kHeartbeat:
      break;
    default:
      connection_->close(std::string("unexpected ") + net::body_name(message) + " from the master");
      break;
  }
}

void Node::handle_challenge(wire::Envelope& message) {
  if (phase_ != Phase::awaiting_challenge) {
    connection_->close("a second challenge from the master");
    return;
  }
  const wire::Challenge& challenge = message.challenge();
  if (challenge.secret_required() && !options_.secret) {
    stop(kExitRefused,
         "the master requires the installation's shared secret: start this node with --secret-file FILE (the file "
         "the config's master.secret_file names)");
    return;
  }
  wire::Envelope hello;
  hello.set_protocol_version(options_.protocol_version);
  hello.mutable_hello()->set_node_id(options_.id);
  hello.mutable_hello()->add_capabilities("render");
  if (options_.secret) {
    const std::string& nonce = challenge.nonce();
    const auto mac =
        net::hello_mac(*options_.secret, std::span(reinterpret_cast<const std::uint8_t*>(nonce.data()), nonce.size()),
                       options_.id, options_.protocol_version);
    hello.mutable_hello()->set_nonce_mac(mac.data(), mac.size());
  }
  connection_->send(hello);
  phase_ = Phase::awaiting_welcome;
}

void Node::handle_welcome(const wire::Welcome& welcome) {
  auto job = protocol::decode_welcome(welcome, options_.id);
  if (!job) {
    stop(kExitRefused, "the master's welcome cannot be used: " + job.error());
    return;
  }
  if (auto configured = renderer_.configure(job.value()); !configured) {
    stop(kExitRefused, "cannot drive projector '" + options_.id + "': " + configured.error());
    return;
  }
  frame_period_ = job.value().frame_period;
  heartbeat_ = std::max(job.value().heartbeat, milliseconds(10));
  liveness_timeout_ = job.value().liveness_timeout;
  light_count_ = job.value().light_count;
  wire::Envelope envelope;
  envelope.mutable_configured()->set_renderer(renderer_.description());
  connection_->send(envelope);
  phase_ = Phase::awaiting_state;
  connection_->set_deadline(kHandshakeTimeout, "no state from the master within 5 s of being configured");
  const config::Projector& p = job.value().job.self();
  log_.info("driving '{}': {}×{} px on screen '{}', eye {}, frame period {:.3f} ms; {}", p.id, p.width, p.height,
            job.value().job.screen().id, config::to_string(p.eye), static_cast<double>(frame_period_) / 1e6,
            renderer_.description());
}

void Node::handle_resync(const wire::Resync& resync) {
  auto state = scene::from_snapshot(resync.snapshot());
  if (!state) {
    connection_->close("bad snapshot from the master: " + state.error());
    return;
  }
  if (scene::state_hash(state.value()) != resync.state_hash()) {
    connection_->close("the master's snapshot does not match its hash");
    return;
  }
  state_ = std::move(state).value();
  past_frames_.clear();
  next_frame_ = resync.next_frame_id();
  if (phase_ == Phase::joined) {
    // A repair between frames: the frame already rendered still swaps.
    log_.info("state resynchronized at frame {}", next_frame_);
    return;
  }
  rendered_any_ = false;
  phase_ = Phase::joined;
  estimator_ = clock::OffsetEstimator{};  // samples from an earlier connection may be from another master
  unreachable_ = false;
  attempts_ = 0;
  backoff_ = milliseconds(100);
  connection_->cancel_deadline();
  connection_->set_liveness_timeout(liveness_timeout_,
                                    "master silent for " + std::to_string(liveness_timeout_.count()) + " ms");
  log_.info("joined at frame {}", next_frame_);
  // A quick burst of pings to get a clock offset before the first swap.
  pings_in_burst_ = kPingBurst;
  send_ping();
}

void Node::handle_frame_begin(const wire::FrameBegin& begin) {
  if (begin.frame_id() != next_frame_) {
    log_.warn("frame ids jumped from {} to {}", next_frame_, begin.frame_id());
  }
  next_frame_ = begin.frame_id() + 1;
  if (auto applied = scene::apply_delta(state_, begin.delta()); !applied) {
    connection_->close("cannot apply frame " + std::to_string(begin.frame_id()) + ": " + applied.error());
    return;
  }
  if (options_.corrupt_state_at_frame != 0 && begin.frame_id() == options_.corrupt_state_at_frame) {
    state_.eye_now.x += 1e-3;
  }
  const std::uint64_t hash = scene::state_hash(state_);
  if (hash != begin.state_hash()) {
    log_.warn("state hash {:016x} differs from the master's {:016x} at frame {}", hash, begin.state_hash(),
              begin.frame_id());
  }
  // A node that lags shows an older frame's content (the light share applies at
  // once: it is how this node's light is split, not content).
  const wire::FrameBegin* shown = &begin;
  const scene::SceneState* shown_state = &state_;
  if (options_.lag_frames > 0) {
    past_frames_.push_back({begin, state_});
    while (past_frames_.size() > options_.lag_frames + 1) past_frames_.pop_front();
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
      connection_->close("frame " + std::to_string(begin.frame_id()) + ": " + focus.error());
      return;
    }
    input.focus = focus.value();
  }
  std::optional<protocol::LightShare> share;
  if (begin.has_lights()) {
    auto decoded = protocol::decode_light_share(begin.lights(), light_count_);
    if (!decoded) {
      connection_->close("frame " + std::to_string(begin.frame_id()) + ": lights: " + decoded.error());
      return;
    }
    share = std::move(decoded).value();
    input.lights = &*share;
  }
  const clock::Nanos started = clock::monotonic_now();
  renderer_.render(input);
  const clock::Nanos render_time = clock::monotonic_now() - started;
  last_rendered_ = begin.frame_id();
  last_content_frame_ = shown->frame_id();
  rendered_any_ = true;

  wire::Envelope envelope;
  auto& ready = *envelope.mutable_frame_ready();
  ready.set_frame_id(begin.frame_id());
  ready.set_render_ns(render_time);
  ready.set_state_hash(hash);
  connection_->send(envelope);
}

void Node::handle_swap(const wire::FrameSwap& swap) {
  if (!rendered_any_ || swap.frame_id() != last_rendered_) {
    log_.warn("swap for frame {} but the last rendered frame is {}; not presenting", swap.frame_id(), last_rendered_);
    return;
  }
  const std::optional<clock::ClockEstimate> estimate = estimator_.at(options_.clock.now());
  const clock::Nanos to_master = estimate ? estimate->offset : 0;
  const clock::Nanos local_deadline = swap.present_deadline_ns() - to_master;
  // Never wait on a deadline from a broken or hostile master for longer than a few
  // frames: this wait holds the event loop.
  const clock::Nanos now = clock::monotonic_now();
  const clock::Nanos longest = std::max<clock::Nanos>(4 * frame_period_, 100 * clock::kNanosPerMilli);
  clock::Nanos deadline = options_.clock.to_monotonic(local_deadline);
  if (deadline > now + longest) {
    log_.warn("swap for frame {} asks to present {:.1f} ms from now; presenting in {:.1f} ms", swap.frame_id(),
              static_cast<double>(deadline - now) / 1e6, static_cast<double>(longest) / 1e6);
    deadline = now + longest;
  }
  // Held up past the next frame's time (the process was stopped, the machine
  // stalled): showing it now would put an old frame beside its partners' new one.
  // Checked again after the wait, which a stop can stretch as well.
  const auto stale = [&](clock::Nanos at) {
    if (at <= deadline + frame_period_) return false;
    log_.warn("frame {}'s present deadline passed {:.1f} ms ago: not showing a stale frame", swap.frame_id(),
              static_cast<double>(at - deadline) / 1e6);
    return true;
  };
  if (stale(now)) return;
  clock::sleep_until_monotonic(deadline, options_.present_spin.count() * clock::kNanosPerMicro);
  if (stale(clock::monotonic_now())) return;
  renderer_.present();
  const clock::Nanos monotonic = clock::monotonic_now();
  const clock::Nanos local = options_.clock.to_local(monotonic);
  // The offset drifts while the node waits for the deadline: convert at this instant.
  const std::optional<clock::ClockEstimate> now_estimate = estimator_.at(local);
  const clock::Nanos now_offset = now_estimate ? now_estimate->offset : 0;
  const clock::Nanos presented = local + now_offset;
  // Nodes sharing a machine present at the same instant: let the others on this
  // core show theirs before this one does its bookkeeping.
  std::this_thread::yield();

  wire::Envelope envelope;
  auto& report = *envelope.mutable_presented();
  report.set_frame_id(swap.frame_id());
  report.set_presented_ns(presented);
  report.set_content_frame_id(last_content_frame_);
  report.set_clock_offset_ns(now_offset);
  if (now_estimate) {
    report.set_clock_rtt_ns(now_estimate->round_trip);
    report.set_clock_drift_ppm(now_estimate->drift_ppm);
    report.set_clock_error_bound_ns(now_estimate->error_bound);
  }
  if (options_.clock.skewed()) {
    report.set_clock_truth_known(true);
    report.set_clock_true_error_ns(now_offset - (monotonic - local));
  }
  connection_->send(envelope);
  log_.debug("presented frame {} at master time {} ns ({:+.1f} µs from the deadline)", swap.frame_id(), presented,
             static_cast<double>(presented - swap.present_deadline_ns()) / 1e3);
}

void Node::send_ping() {
  if (phase_ != Phase::joined || !connection_) return;
  wire::Envelope envelope;
  envelope.mutable_ping()->set_t1(options_.clock.now());
  connection_->send(envelope);
  if (pings_in_burst_ > 0) --pings_in_burst_;
  // Ten a second: the drift fit wants a quiet sample in each of its buckets.
  schedule_pings(pings_in_burst_ > 0 ? milliseconds(5) : std::min(heartbeat_, kPingInterval));
}

void Node::schedule_pings(milliseconds interval) {
  ping_timer_.expires_after(interval);
  ping_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) send_ping();
  });
}

void Node::handle_pong(const wire::Pong& pong) {
  const clock::PingSample sample{pong.t1(), pong.t2(), pong.t3(), options_.clock.now()};
  if (!estimator_.add(sample)) log_.debug("dropped an impossible clock sample");
}

void Node::on_closed(const std::string& reason) {
  ping_timer_.cancel();
  if (phase_ == Phase::stopped) return;
  const bool was_joined = phase_ == Phase::joined;
  phase_ = Phase::disconnected;
  if (was_joined) {
    log_.warn("lost the master: {}; {} while reconnecting", reason,
              options_.hold_last_frame ? "holding the last frame" : "showing black");
    if (!options_.hold_last_frame) renderer_.show_black();
  } else {
    log_.info("connection to the master closed during the handshake: {}", reason);
  }
  retry_later(reason);
}

void Node::on_signal(int signal) {
  if (connection_ && connection_->is_open()) {
    wire::Envelope goodbye;
    goodbye.mutable_goodbye()->set_reason(std::string("node ") + strsignal(signal));
    connection_->send(goodbye);
  }
  stop(kExitOk, std::string("stopping on ") + strsignal(signal));
}

void Node::stop(int exit_code, const std::string& reason) {
  if (phase_ == Phase::stopped) return;
  phase_ = Phase::stopped;
  exit_code_ = exit_code;
  if (exit_code == kExitOk) {
    log_.info("{}", reason);
  } else {
    log_.error("{}", reason);
  }
  retry_timer_.cancel();
  ping_timer_.cancel();
  connect_timer_.cancel();
  signals_.cancel();
  resolver_.cancel();
  if (connecting_) {
    boost::system::error_code ignored;
    connecting_->close(ignored);
  }
  if (connection_ && connection_->is_open()) {
    // The master logs why a node leaves: a node that cannot render says so there too.
    if (exit_code != kExitOk) {
      wire::Envelope goodbye;
      goodbye.mutable_goodbye()->set_reason(reason);
      connection_->send(goodbye);
    }
    connection_->close_after_sending(reason);
  }
}

}  // namespace optique::node
