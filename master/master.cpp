#include "master/master.h"

#include <google/protobuf/util/json_util.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <random>

#include "config/light_list.h"
#include "net/envelope.h"
#include "protocol/welcome.h"

namespace optique::master {
namespace {

using std::chrono::milliseconds;

bool is_loopback(const asio::ip::address& address) {
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    return asio::ip::make_address_v4(asio::ip::v4_mapped, address.to_v6()).is_loopback();
  }
  return address.is_loopback();
}

std::string format_us(double us) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.0f µs", us);
  return buffer;
}

}  // namespace

Master::Master(asio::io_context& io, MasterOptions options, spdlog::logger& log)
    : io_(io),
      options_(std::move(options)),
      log_(log),
      settings_(options_.config.installation.master),
      acceptor_(io),
      accept_retry_timer_(io),
      signals_(io, SIGINT, SIGTERM),
      frame_timer_(io),
      barrier_timer_(io),
      phase_timer_(io),
      housekeeping_timer_(io),
      heartbeat_timer_(io),
      status_(options_.status_line) {
  for (const auto& projector : options_.config.installation.projectors)
    slots_.push_back({&projector, nullptr, std::nullopt});
}

Master::~Master() = default;

Result<void> Master::start() {
  const auto& installation = options_.config.installation;
  const std::size_t light_count = options_.scene.definition.lights.size();
  if (auto problems = LightSwitches::check(installation.scene, light_count); !problems.empty()) {
    return Error{config::describe_problems(problems, options_.config.path)};
  }
  authority_.emplace(options_.scene.definition.objects, installation.viewer, settings_.frame_rate,
                     LightSwitches::from_config(installation.scene));
  frame_period_ = authority_->frame_period();
  current_state_ = authority_->state_at_frame(0);
  current_hash_ = scene::state_hash(current_state_);
  light_plan_.emplace(installation, options_.scene.definition);
  // Until nodes come, plan as if all were up: each node's welcome then carries a
  // sensible share.
  light_plan_->rebalance(std::vector<bool>(slots_.size(), true), current_state_, current_state_.eye_now, true);
  focus_ = FocusSchedule::make(installation);

  std::vector<std::string> ids;
  for (const Slot& s : slots_) ids.push_back(s.projector->id);
  if (!options_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(options_.out_dir) / "logs", ec);
    if (ec) return Error{"cannot create the output folder '" + options_.out_dir + "': " + ec.message()};
    const auto csv_path = std::filesystem::path(options_.out_dir) / "frames.csv";
    csv_.open(csv_path);
    if (!csv_) return Error{"cannot write " + csv_path.string()};
  }
  recorder_.emplace(ids, csv_.is_open() ? &csv_ : nullptr);

  // Listen.
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(settings_.listen, ec);
  if (ec) return Error{"master.listen: '" + settings_.listen + "' is not an address"};
  const asio::ip::tcp::endpoint endpoint(address, static_cast<std::uint16_t>(settings_.port));
  acceptor_.open(endpoint.protocol(), ec);
  if (!ec) acceptor_.set_option(asio::ip::tcp::acceptor::reuse_address(true), ec);
  if (!ec) acceptor_.bind(endpoint, ec);
  if (!ec) acceptor_.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) {
    return Error{"cannot listen on " + settings_.listen + ":" + std::to_string(settings_.port) + ": " + ec.message()};
  }
  port_ = acceptor_.local_endpoint().port();
  if (!options_.port_file.empty()) {
    const std::string temp = options_.port_file + ".tmp";
    std::ofstream(temp) << port_ << "\n";
    std::error_code renamed;
    std::filesystem::rename(temp, options_.port_file, renamed);
    if (renamed) return Error{"cannot write the port file '" + options_.port_file + "': " + renamed.message()};
  }
  std::string id_list;
  for (const auto& id : ids) id_list += (id_list.empty() ? "" : ", ") + id;
  log_.info("listening on {}:{}; waiting for {} node(s): {}", settings_.listen, port_, slots_.size(), id_list);
  if (options_.secret) {
    log_.info("nodes must prove they hold the shared secret in {}", options_.secret_path);
  } else {
    log_.warn("no shared secret (master.secret_file): accepting nodes from this machine's loopback addresses only");
  }

  if (options_.local) {
    launcher_.emplace(options_.node_binary);
    for (const Slot& s : slots_) {
      std::vector<std::string> args{"--master",    "127.0.0.1:" + std::to_string(port_),
                                    "--id",        s.projector->id,
                                    "--log-level", options_.node_log_level};
      if (!options_.secret_path.empty()) {
        args.push_back("--secret-file");
        args.push_back(options_.secret_path);
      }
      if (!options_.out_dir.empty()) {
        args.push_back("--capture-dir");
        args.push_back((std::filesystem::path(options_.out_dir) / "nodes" / s.projector->id).string());
      }
      args.insert(args.end(), options_.node_args.begin(), options_.node_args.end());
      auto pid = launcher_->spawn(s.projector->id, args, node_log_path(s.projector->id));
      if (!pid) return Error{"cannot start the node for projector '" + s.projector->id + "': " + pid.error()};
      log_.debug("started node '{}' as pid {}", s.projector->id, pid.value());
    }
  }

  signals_.async_wait([this](const boost::system::error_code& error, int signal) {
    if (!error) on_signal(signal);
  });
  accept_next();
  housekeeping();
  send_heartbeats();
  phase_timer_.expires_after(settings_.startup_timeout);
  phase_timer_.async_wait([this](const boost::system::error_code& error) {
    if (error || state_ != RunState::starting) return;
    if (nodes_up() == 0) {
      fail("no node connected within " + std::to_string(settings_.startup_timeout.count()) + " ms");
      return;
    }
    std::string missing;
    for (const Slot& s : slots_) {
      if (!s.session) missing += (missing.empty() ? "" : ", ") + s.projector->id;
    }
    log_.warn("starting without {} (not connected after {} ms); they join when they come", missing,
              settings_.startup_timeout.count());
    start_frames();
  });
  return {};
}

// ---------------------------------------------------------------- connections

void Master::accept_next() {
  acceptor_.async_accept([this](const boost::system::error_code& error, asio::ip::tcp::socket socket) {
    if (error) {
      if (error == asio::error::operation_aborted || !acceptor_.is_open() || state_ == RunState::done) return;
      // Out of file descriptors and the like: try again shortly, and say so once
      // per failure streak rather than thousands of times a second.
      if (!accept_failing_) log_.warn("accept failed: {}; retrying every 100 ms", error.message());
      accept_failing_ = true;
      accept_retry_timer_.expires_after(milliseconds(100));
      accept_retry_timer_.async_wait([this](const boost::system::error_code& e) {
        if (!e) accept_next();
      });
      return;
    }
    if (accept_failing_) log_.info("accepting connections again");
    accept_failing_ = false;
    if (state_ == RunState::starting || state_ == RunState::running) on_connection(std::move(socket));
    accept_next();
  });
}

void Master::on_connection(asio::ip::tcp::socket socket) {
  boost::system::error_code error;
  const asio::ip::tcp::endpoint peer = socket.remote_endpoint(error);
  if (error) return;  // gone already
  const std::string peer_text = peer.address().to_string() + ":" + std::to_string(peer.port());
  if (!options_.secret && !is_loopback(peer.address())) {
    log_.warn(
        "refused connection from {}: no shared secret is configured (master.secret_file), so only nodes on "
        "this machine are accepted",
        peer_text);
    ++refused_connections_;
    return;  // the socket closes as it goes out of scope
  }
  const auto pending = static_cast<std::size_t>(
      std::count_if(sessions_.begin(), sessions_.end(), [](const auto& s) { return s->phase == Phase::handshake; }));
  if (pending >= settings_.max_pending_connections) {
    log_.warn(
        "refused connection from {}: {} connections are already waiting to authenticate "
        "(master.max_pending_connections)",
        peer_text, pending);
    ++refused_connections_;
    return;
  }
  auto session = std::make_shared<Session>();
  // Until a peer has said who it is, only a hello-sized frame is accepted: nobody
  // makes the master parse megabytes before authenticating.
  session->connection = net::Connection::create(std::move(socket), kMaxHelloBytes);
  sessions_.push_back(session);
  std::weak_ptr<Session> weak = session;
  session->connection->start({
      [this, weak](wire::Envelope& message) {
        if (auto s = weak.lock()) on_message(s, message);
      },
      [this, weak](const std::string& reason) {
        if (auto s = weak.lock()) on_closed(s, reason);
      },
  });
  session->connection->set_deadline(
      settings_.handshake_timeout,
      "no valid hello within " + std::to_string(settings_.handshake_timeout.count()) + " ms");
  wire::Envelope challenge;
  session->nonce = net::random_nonce();
  challenge.mutable_challenge()->set_nonce(session->nonce.data(), session->nonce.size());
  challenge.mutable_challenge()->set_secret_required(options_.secret.has_value());
  session->connection->send(challenge);
  log_.debug("connection from {}", session->connection->peer());
}

void Master::on_message(const std::shared_ptr<Session>& session, wire::Envelope& message) {
  const clock::Nanos received = clock::monotonic_now();
  if (session->phase == Phase::handshake) {
    handle_hello(session, message);
    return;
  }
  if (message.protocol_version() != net::kProtocolVersion) {
    session->connection->close("protocol version changed mid-connection");
    return;
  }
  switch (message.body_case()) {
    case wire::Envelope::kPing: {
      wire::Envelope pong;
      auto& p = *pong.mutable_pong();
      p.set_t1(message.ping().t1());
      p.set_t2(received);
      p.set_t3(clock::monotonic_now());
      session->connection->send(pong);
      break;
    }
    case wire::Envelope::kHeartbeat:
      break;
    case wire::Envelope::kConfigured:
      if (session->phase != Phase::configuring) {
        session->connection->close("configured twice");
        break;
      }
      handle_configured(*session, message.configured());
      break;
    case wire::Envelope::kFrameReady:
      handle_ready(*session, message.frame_ready(), received);
      break;
    case wire::Envelope::kPresented:
      handle_presented(*session, message.presented());
      break;
    case wire::Envelope::kGoodbye:
      session->connection->close("node said goodbye (" + message.goodbye().reason() + ")");
      break;
    default:
      session->connection->close(std::string("unexpected ") + net::body_name(message) + " from a node");
      break;
  }
}

void Master::refuse(Session& session, const std::string& node_id, const std::string& reason, bool retriable) {
  log_.warn("refused node '{}' from {}: {}", node_id, session.connection->peer(), reason);
  session.refused = true;
  ++refused_connections_;
  wire::Envelope envelope;
  envelope.set_protocol_version(net::kProtocolVersion);
  envelope.mutable_refuse()->set_reason(reason);
  envelope.mutable_refuse()->set_retriable(retriable);
  session.connection->send(envelope);
  session.connection->close_after_sending("refused: " + reason);
}

void Master::handle_hello(const std::shared_ptr<Session>& session, wire::Envelope& message) {
  if (message.body_case() != wire::Envelope::kHello) {
    refuse(*session, "?", std::string("expected hello, got ") + net::body_name(message), false);
    return;
  }
  const wire::Hello& hello = message.hello();
  if (message.protocol_version() != net::kProtocolVersion) {
    refuse(*session, hello.node_id(),
           "protocol version mismatch: node speaks v" + std::to_string(message.protocol_version()) +
               ", master speaks v" + std::to_string(net::kProtocolVersion) +
               "; run the same optique version on master and nodes",
           false);
    return;
  }
  if (options_.secret) {
    const std::string& mac = hello.nonce_mac();
    if (mac.empty()) {
      refuse(*session, hello.node_id(),
             "this master requires the installation's shared secret: start the node with --secret-file", false);
      return;
    }
    if (!net::verify_hello_mac(*options_.secret, session->nonce, hello.node_id(), message.protocol_version(),
                               std::span(reinterpret_cast<const std::uint8_t*>(mac.data()), mac.size()))) {
      refuse(*session, hello.node_id(), "authentication failed: the node's secret does not match the master's", false);
      return;
    }
  }
  std::optional<std::size_t> slot;
  std::string known;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    if (slots_[i].projector->id == hello.node_id()) slot = i;
    known += (known.empty() ? "" : ", ") + slots_[i].projector->id;
  }
  if (!slot) {
    refuse(*session, hello.node_id(),
           "unknown projector id '" + hello.node_id() + "' (this installation has: " + known + ")", false);
    return;
  }
  Slot& target = slots_[*slot];
  if (target.session) {
    refuse(*session, hello.node_id(),
           "projector '" + hello.node_id() + "' is already driven by the node at " + target.session->connection->peer(),
           true);
    return;
  }

  target.session = session;
  session->slot = slot;
  session->phase = Phase::configuring;
  session->connection->set_max_payload_bytes(settings_.max_message_bytes);
  // Setting up a GL context and compiling shaders can take seconds on a loaded
  // machine; the node is silent meanwhile.
  session->connection->set_deadline(
      kConfigureTimeout, "node did not finish configuring within " + std::to_string(kConfigureTimeout.count()) + " s");

  const LightShare* share = light_plan_->share(*slot);
  wire::Envelope envelope;
  *envelope.mutable_welcome() = protocol::encode_welcome(
      options_.config.installation, *slot, options_.scene.content_sha256,
      static_cast<std::uint32_t>(options_.scene.definition.lights.size()), frame_period_, share);
  // Its first frame repeats the share, so the log tells from which frame each node
  // draws what (and a share changed while it set itself up still reaches it).
  if (share != nullptr) target.sent_share.reset();
  session->connection->send(envelope);
  log_.debug("node '{}' from {} is configuring", hello.node_id(), session->connection->peer());
}

void Master::handle_configured(Session& session, const wire::Configured& configured) {
  session.connection->cancel_deadline();
  session.connection->set_liveness_timeout(
      settings_.liveness_timeout, "node silent for " + std::to_string(settings_.liveness_timeout.count()) + " ms");
  send_resync(session);
  session.phase = Phase::joined;
  recorder_->node_joined(*session.slot);
  rebalance_lights(true);
  log_.info("node '{}' joined from {} with {} ({}/{} up)", slot_id(*session.slot), session.connection->peer(),
            configured.renderer(), nodes_up(), slots_.size());
  if (state_ == RunState::starting && nodes_up() == slots_.size()) start_frames();
}

// The state as of the last frame begun; the next FrameBegin's delta applies to it.
void Master::send_resync(Session& session) {
  wire::Envelope envelope;
  auto& resync = *envelope.mutable_resync();
  *resync.mutable_snapshot() = scene::to_snapshot(current_state_);
  resync.set_next_frame_id(next_frame_);
  resync.set_state_hash(current_hash_);
  session.connection->send(envelope);
}

void Master::on_closed(const std::shared_ptr<Session>& session, const std::string& reason) {
  std::erase(sessions_, session);
  if (!session->slot) {
    if ((state_ == RunState::starting || state_ == RunState::running) && !session->refused) {
      log_.warn("refused connection from {}: {}", session->connection->peer(), reason);
      ++refused_connections_;
    }
  } else {
    const std::size_t slot = *session->slot;
    slots_[slot].session.reset();
    if (state_ == RunState::starting || state_ == RunState::running) {
      log_.warn("node '{}' left: {} ({}/{} up)", slot_id(slot), reason, nodes_up(), slots_.size());
    } else {
      log_.debug("node '{}' closed: {}", slot_id(slot), reason);
    }
    std::erase(ready_for_swap_, slot);  // a node that is gone is not told to swap
    if (state_ != RunState::closing && state_ != RunState::done) rebalance_lights(true);
    if (barrier_.active()) {
      barrier_.leave(slot);
      if (barrier_.complete()) swap();
    }
  }
  if (state_ == RunState::closing && sessions_.empty() && (!launcher_ || launcher_->running() == 0)) finish();
}

// ---------------------------------------------------------------- frames

void Master::start_frames() {
  if (state_ != RunState::starting) return;
  state_ = RunState::running;
  phase_timer_.cancel();
  log_.info("starting frames at {} Hz with {}/{} node(s){}", settings_.frame_rate, nodes_up(), slots_.size(),
            options_.frames ? " for " + std::to_string(options_.frames) + " frames" : std::string());
  schedule_origin_ = clock::monotonic_now();
  schedule_origin_frame_ = next_frame_;
  begin_frame();
}

void Master::begin_frame() {
  if (state_ != RunState::running) return;
  const std::uint64_t frame = next_frame_;
  if (options_.frames != 0 && frame >= options_.frames) {
    drain("ran " + std::to_string(options_.frames) + " frames");
    return;
  }
  scene::SceneState state = authority_->state_at_frame(frame);
  wire::Envelope envelope;
  auto& begin = *envelope.mutable_frame_begin();
  begin.set_frame_id(frame);
  begin.set_simulation_time_ns(authority_->simulation_time(frame));
  *begin.mutable_delta() = scene::make_delta(current_state_, state);
  const bool lights_switched = begin.delta().lights_off_size() > 0 || begin.delta().lights_on_size() > 0;
  if (lights_switched) log_light_switches(frame, begin.delta(), state);
  current_state_ = std::move(state);
  current_hash_ = scene::state_hash(current_state_);
  begin.set_state_hash(current_hash_);
  begin.set_capture(options_.capture_every != 0 && frame % options_.capture_every == 0);
  begin.set_present_time_ns(schedule_origin_ +
                            static_cast<clock::Nanos>(frame + 1 - schedule_origin_frame_) * frame_period_);
  if (focus_) {
    *begin.mutable_focus() =
        protocol::to_wire(focus_->at(static_cast<double>(begin.simulation_time_ns()) / 1e9, options_.scene.definition,
                                     current_state_, current_state_.eye_now));
  }
  // The scene moves: about once a second, see whether another split of the
  // automatic groups' lights would finish clearly sooner.
  const auto frames_per_second = static_cast<std::uint64_t>(std::max(1.0, settings_.frame_rate));
  if (lights_switched) {
    rebalance_lights(true);
  } else if (frame % frames_per_second == 0) {
    rebalance_lights(false);
  }

  std::vector<std::size_t> sent;
  std::vector<std::size_t> waited;
  const clock::Nanos begin_sent = clock::monotonic_now();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const std::shared_ptr<Session> session = slots_[i].session;
    if (!session || session->phase == Phase::handshake || session->phase == Phase::configuring) continue;
    if (session->phase == Phase::joined) session->phase = Phase::in_barrier;
    const LightShare* share = light_plan_->share(i);
    if (share != nullptr && slots_[i].sent_share != *share) {
      // A new share applies from this frame on, on every node of the group at once.
      wire::Envelope with_share = envelope;
      *with_share.mutable_frame_begin()->mutable_lights() = protocol::to_wire(*share);
      session->connection->send(with_share);
      slots_[i].sent_share = *share;
      log_.info("node '{}' draws lights [{}]{} from frame {}", slot_id(i), config::format_light_list(share->lights),
                share->ambient ? " and ambient" : "", frame);
    } else {
      session->connection->send(envelope);
    }
    sent.push_back(i);
    if (session->phase == Phase::in_barrier) waited.push_back(i);
  }
  recorder_->frame_begun(frame, begin_sent, sent);
  if (frame > 0) recorder_->finalize_before(frame - 1);  // the previous frame may still get Presented
  next_frame_ = frame + 1;
  ready_for_swap_.clear();
  barrier_.begin(frame, std::move(waited));
  if (barrier_.complete()) {
    swap();
    return;
  }
  barrier_timer_.expires_after(settings_.frame_timeout);
  barrier_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) on_barrier_timeout();
  });
}

void Master::handle_ready(Session& session, const wire::FrameReady& ready, clock::Nanos received) {
  const std::size_t slot = *session.slot;
  recorder_->ready(ready.frame_id(), slot, received, ready.render_ns());
  if (ready.frame_id() + 1 == next_frame_ && ready.state_hash() != current_hash_) {
    recorder_->hash_mismatch(slot);
    log_.warn("node '{}' reports state hash {:016x} for frame {}, master has {:016x}: sending it a fresh snapshot",
              slot_id(slot), ready.state_hash(), ready.frame_id(), current_hash_);
    send_resync(session);  // the next FrameBegin's delta applies to it, so the next frame matches again
  }
  const bool current = barrier_.active() && ready.frame_id() == barrier_.frame();
  if (session.phase == Phase::out_of_barrier) {
    // It answers again: wait for it from the next frame on, and if this answer is
    // for the frame being decided, it swaps with the others.
    session.phase = Phase::joined;
    log_.info("node '{}' answers again (frame {}); back in the barrier from the next frame", slot_id(slot),
              ready.frame_id());
    if (current) ready_for_swap_.push_back(slot);
  } else if (current && barrier_.ready(slot)) {
    ready_for_swap_.push_back(slot);
  }
  if (!current) log_.debug("late ready from '{}' for frame {}", slot_id(slot), ready.frame_id());
  if (barrier_.complete()) swap();
}

void Master::on_barrier_timeout() {
  if (!barrier_.active()) return;
  const bool drop = settings_.straggler_policy == config::StragglerPolicy::drop;
  for (std::size_t slot : barrier_.waiting_for()) {
    recorder_->node_missed_barrier(slot);
    if (Session* session = slots_[slot].session.get()) session->phase = Phase::out_of_barrier;
    log_.warn("node '{}' was not ready for frame {} within {} ms: taken out of the barrier; {}", slot_id(slot),
              barrier_.frame(), settings_.frame_timeout.count(),
              drop ? "the frame is dropped everywhere" : "the others show the frame");
  }
  if (drop) {
    recorder_->frame_dropped(barrier_.frame());
    ready_for_swap_.clear();  // nobody shows it: every projector keeps the previous frame
  }
  swap();
}

void Master::swap() {
  barrier_timer_.cancel();
  const std::uint64_t frame = barrier_.frame();
  barrier_.end();
  wire::Envelope envelope;
  auto& swap = *envelope.mutable_swap();
  swap.set_frame_id(frame);
  const clock::Nanos sent = clock::monotonic_now();
  swap.set_present_deadline_ns(sent + std::chrono::nanoseconds(settings_.present_lead).count());
  for (std::size_t slot : ready_for_swap_) {
    if (Session* session = slots_[slot].session.get()) session->connection->send(envelope);
  }
  recorder_->swapped(frame, sent, ready_for_swap_);
  ready_for_swap_.clear();
  update_status();
  if (state_ == RunState::draining) {
    wait_for_last_presents(true);
    return;
  }
  schedule_next_frame(sent);
}

void Master::schedule_next_frame(clock::Nanos now) {
  clock::Nanos due = schedule_origin_ + static_cast<clock::Nanos>(next_frame_ - schedule_origin_frame_) * frame_period_;
  if (due < now) {
    // Behind schedule: start again from now instead of rushing frames to catch up.
    schedule_origin_ = now;
    schedule_origin_frame_ = next_frame_;
    due = now;
  }
  frame_timer_.expires_after(std::chrono::nanoseconds(due - clock::monotonic_now()));
  frame_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) begin_frame();
  });
}

void Master::handle_presented(Session& session, const wire::Presented& presented) {
  recorder_->presented(presented.frame_id(), *session.slot, presented.presented_ns(), presented.content_frame_id());
  report::ClockReport clock;
  clock.set_offset_ns(presented.clock_offset_ns());
  clock.set_drift_ppm(presented.clock_drift_ppm());
  clock.set_round_trip_ns(presented.clock_rtt_ns());
  clock.set_error_bound_ns(presented.clock_error_bound_ns());
  recorder_->clock_estimated(
      presented.frame_id(), *session.slot, clock,
      presented.clock_truth_known() ? std::optional(presented.clock_true_error_ns()) : std::nullopt);
}

// ---------------------------------------------------------------- stopping

void Master::drain(const std::string& reason) {
  if (state_ != RunState::starting && state_ != RunState::running) return;
  stopped_because_ = reason;
  const bool frames_ran = state_ == RunState::running;
  state_ = RunState::draining;
  frame_timer_.cancel();
  phase_timer_.cancel();
  log_.info("stopping: {}", reason);
  // A frame in its barrier finishes first (swap() then comes back here).
  if (!barrier_.active()) wait_for_last_presents(frames_ran);
}

void Master::wait_for_last_presents(bool frames_ran) {
  // The last swap's Presented arrive after its present deadline.
  const auto wait = frames_ran ? std::chrono::duration_cast<milliseconds>(settings_.present_lead) + milliseconds(250)
                               : milliseconds(0);
  phase_timer_.expires_after(wait);
  phase_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) say_goodbye();
  });
}

void Master::say_goodbye() {
  state_ = RunState::closing;
  acceptor_.close();
  wire::Envelope envelope;
  envelope.mutable_goodbye()->set_reason(stopped_because_);
  for (const auto& session : std::vector(sessions_)) {
    session->connection->send(envelope);
    session->connection->close_after_sending("goodbye");
  }
  // Nodes exit on goodbye; whatever is still there after this is stopped harder.
  phase_timer_.expires_after(std::chrono::seconds(3));
  phase_timer_.async_wait([this](const boost::system::error_code& error) {
    if (error || state_ != RunState::closing) return;
    if (launcher_ && launcher_->running() > 0) {
      log_.warn("{} local node(s) still running 3 s after goodbye; terminating them", launcher_->running());
      launcher_->signal_all(SIGTERM);
      phase_timer_.expires_after(std::chrono::seconds(2));
      phase_timer_.async_wait([this](const boost::system::error_code& e) {
        if (!e && state_ == RunState::closing) {
          launcher_->signal_all(SIGKILL);
          finish();
        }
      });
      return;
    }
    finish();
  });
  if (sessions_.empty() && (!launcher_ || launcher_->running() == 0)) finish();
}

void Master::fail(const std::string& reason) {
  log_.error("{}", reason);
  exit_code_ = kExitFailed;
  stopped_because_ = reason;
  say_goodbye();
}

void Master::finish() {
  if (state_ == RunState::done) return;
  state_ = RunState::done;
  status_.clear();
  frame_timer_.cancel();
  barrier_timer_.cancel();
  phase_timer_.cancel();
  housekeeping_timer_.cancel();
  heartbeat_timer_.cancel();
  accept_retry_timer_.cancel();
  signals_.cancel();
  if (launcher_) {
    for (const ChildExit& exit : launcher_->reap()) {
      log_.debug("node '{}' (pid {}) {}", exit.id, exit.pid, exit.describe());
    }
  }
  recorder_->finalize_all();
  write_outputs();
  io_.stop();
}

void Master::write_outputs() {
  report::RunReport report = recorder_->report();
  report.set_config_file(options_.config.path);
  report.set_config_sha256(options_.config.sha256);
  report.set_frame_rate(settings_.frame_rate);
  report.set_stopped_because(stopped_because_);
  report.set_connections_refused(refused_connections_);
  const auto& sync = report.sync();
  log_.info("{} frames; barrier round median {} p99 {}; present skew median {} p99 {}; {} frame(s) with a node missing",
            report.frames(), format_us(sync.barrier_round_us().median()), format_us(sync.barrier_round_us().p99()),
            format_us(sync.present_skew_us().median()), format_us(sync.present_skew_us().p99()),
            sync.frames_with_missing_node());
  if (options_.out_dir.empty()) return;
  std::string json;
  google::protobuf::util::JsonPrintOptions print;
  print.add_whitespace = true;
  print.always_print_primitive_fields = true;
  print.preserve_proto_field_names = true;
  const auto status = google::protobuf::util::MessageToJsonString(report, &json, print);
  assert(status.ok());
  (void)status;
  const auto path = std::filesystem::path(options_.out_dir) / "run.json";
  std::ofstream out(path);
  out << json;
  if (!out) {
    log_.error("cannot write {}", path.string());
    exit_code_ = kExitFailed;
    return;
  }
  log_.info("wrote {} and {}", path.string(), (std::filesystem::path(options_.out_dir) / "frames.csv").string());
}

// ---------------------------------------------------------------- periodic

void Master::rebalance_lights(bool force) {
  std::vector<bool> up(slots_.size(), false);
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const auto& session = slots_[i].session;
    up[i] = session && session->phase != Phase::handshake && session->phase != Phase::configuring;
  }
  light_plan_->rebalance(up, current_state_, current_state_.eye_now, force);
}

void Master::log_light_switches(std::uint64_t frame, const wire::StateDelta& delta, const scene::SceneState& state) {
  const auto list = [](const auto& lights) {
    return config::format_light_list(std::vector<std::uint32_t>(lights.begin(), lights.end()));
  };
  std::string what;
  if (delta.lights_off_size() > 0) what = "lights [" + list(delta.lights_off()) + "] go dark";
  if (delta.lights_on_size() > 0) {
    what += (what.empty() ? "" : ", ") + std::string("lights [") + list(delta.lights_on()) + "] come on";
  }
  log_.info("frame {}: {} ({} of {} off)", frame, what, state.lights_off.size(),
            options_.scene.definition.lights.size());
}

void Master::housekeeping() {
  if (launcher_) {
    for (const ChildExit& exit : launcher_->reap()) {
      const std::string log_hint = options_.out_dir.empty() ? std::string() : "; its log: " + node_log_path(exit.id);
      if (state_ == RunState::closing && exit.clean()) {
        log_.debug("node '{}' (pid {}) {}", exit.id, exit.pid, exit.describe());
      } else {
        log_.warn("node '{}' (pid {}) {}{}", exit.id, exit.pid, exit.describe(), log_hint);
      }
      if (state_ == RunState::starting && !exit.clean()) {
        fail("node '" + exit.id + "' stopped before the cluster started" + log_hint);
        return;
      }
    }
    if (state_ == RunState::closing && sessions_.empty() && launcher_->running() == 0) {
      finish();
      return;
    }
  }
  if (state_ == RunState::done) return;
  update_status();
  housekeeping_timer_.expires_after(milliseconds(100));
  housekeeping_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) housekeeping();
  });
}

void Master::send_heartbeats() {
  wire::Envelope envelope;
  envelope.mutable_heartbeat()->set_sent_ns(clock::monotonic_now());
  for (const Slot& slot : slots_) {
    if (slot.session && slot.session->phase != Phase::handshake && slot.session->phase != Phase::configuring) {
      slot.session->connection->send(envelope);
    }
  }
  heartbeat_timer_.expires_after(settings_.heartbeat);
  heartbeat_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) send_heartbeats();
  });
}

void Master::on_signal(int signal) {
  ++interrupts_;
  if (interrupts_ == 1) {
    status_.clear();
    log_.info("{}: finishing the current frame and shutting down (again to stop at once)", strsignal(signal));
    if (state_ == RunState::starting || state_ == RunState::running) {
      drain(std::string("interrupted (") + strsignal(signal) + ")");
    }
  } else {
    log_.warn("{} again: stopping now", strsignal(signal));
    if (launcher_) launcher_->signal_all(SIGKILL);
    stopped_because_ = std::string("interrupted twice (") + strsignal(signal) + ")";
    finish();
    return;
  }
  signals_.async_wait([this](const boost::system::error_code& error, int next) {
    if (!error) on_signal(next);
  });
}

void Master::update_status() {
  if (!status_.enabled()) return;
  const clock::Nanos now = clock::monotonic_now();
  if (now - last_status_ < 250 * clock::kNanosPerMilli) return;
  const double rate = last_status_ == 0 ? 0.0
                                        : static_cast<double>(next_frame_ - status_frame_) * 1e9 /
                                              static_cast<double>(now - last_status_);
  last_status_ = now;
  status_frame_ = next_frame_;
  const std::string total = options_.frames ? std::to_string(options_.frames) : std::string("-");
  char line[200];
  std::snprintf(line, sizeof line, "frame %llu/%s  %.1f Hz  nodes %zu/%zu  skew %.0f us  missing %llu",
                static_cast<unsigned long long>(next_frame_), total.c_str(), rate, nodes_up(), slots_.size(),
                recorder_->last_present_skew_us(),
                static_cast<unsigned long long>(recorder_->frames_with_missing_node()));
  status_.show(line);
}

std::size_t Master::nodes_up() const {
  std::size_t up = 0;
  for (const Slot& s : slots_) up += s.session && s.session->phase != Phase::configuring ? 1 : 0;
  return up;
}

std::string Master::slot_id(std::size_t slot) const { return slots_[slot].projector->id; }

std::string Master::node_log_path(const std::string& id) const {
  if (options_.out_dir.empty()) return {};
  return (std::filesystem::path(options_.out_dir) / "logs" / (id + ".log")).string();
}

}  // namespace optique::master
