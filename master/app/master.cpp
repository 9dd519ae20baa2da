#include "master/app/master.h"

#include <boost/asio/post.hpp>

#include <cassert>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "config/address.h"
#include "master/report_json.h"
#include "master/run_verdict.h"
#include "net/stamped_receive.h"
#include "util/join.h"
#include "util/overloaded.h"

namespace optique::master {

namespace {

// A port chosen by the system (port 0), for whoever started the master: written
// whole under another name and renamed, so a reader never sees half of it.
// `path` empty: not asked for.
Result<void> write_port_file(const std::string& path, unsigned port, const std::string& what) {
  if (path.empty()) return {};
  const std::string temp = path + ".tmp";
  std::ofstream(temp) << port << "\n";
  std::error_code renamed;
  std::filesystem::rename(temp, path, renamed);
  if (renamed) return Error{"cannot write the " + what + " '" + path + "': " + renamed.message()};
  return {};
}

using std::chrono::milliseconds;

}  // namespace

Master::Master(asio::io_context& io, MasterOptions options, spdlog::logger& log)
    : io_(io),
      options_(std::move(options)),
      log_(log),
      listener_(io, log),
      tracker_socket_(io),
      signals_(io, SIGINT, SIGTERM),
      housekeeping_timer_(io),
      status_(options_.status_line) {
  for (auto& timer : timers_) timer = std::make_unique<asio::steady_timer>(io);
}

Master::~Master() = default;

Result<void> Master::listen_to_tracker(const config::Tracking& tracking, double frame_rate) {
  boost::system::error_code ec;
  const auto address = asio::ip::make_address(tracking.listen, ec);
  if (ec) return Error{"viewer.tracking.listen: '" + tracking.listen + "' is not an address"};
  const asio::ip::udp::endpoint endpoint(address, tracking.port);
  tracker_socket_.open(endpoint.protocol(), ec);
  if (!ec) tracker_socket_.bind(endpoint, ec);  // no reuse: a second receiver on the port is an error, said
  if (ec) {
    return Error{"viewer.tracking: cannot receive on " + tracking.listen + ":" + std::to_string(tracking.port) +
                 " (UDP): " + ec.message()};
  }
  log_.info("tracking: DTrack's ASCII output on {}:{} (UDP), body {}, predicted {}", tracking.listen,
            tracker_socket_.local_endpoint().port(), tracking.body, config::to_string(tracking.prediction));
  // Each sample is stamped when the kernel received it, not when a thread got to it.
  if (!net::enable_receive_stamps(tracker_socket_.native_handle())) {
    log_.warn("tracking: the kernel does not stamp datagrams here; samples are stamped when read");
  }
  tracker_socket_.non_blocking(true, ec);
  // The read budget is per frame.
  const auto period = static_cast<clock::Nanos>(1e9 / std::max(frame_rate, 1.0));
  tracker_receiver_ =
      std::make_unique<TrackerReceiver>(tracker_socket_.native_handle(), tracking::DTrackReader(tracking, period),
                                        [this] { asio::post(io_, [this] { take_tracker_input(); }); });
  return {};
}

void Master::take_tracker_input() {
  if (!finished_ && tracker_receiver_) carry_out(protocol_->tracker_input(tracker_receiver_->take()));
}

Result<void> Master::start() {
  started_ = clock::monotonic_now();
  const config::Installation& installation = options_.config.installation;
  const config::MasterSettings& settings = installation.master;
  std::vector<std::string> ids;
  for (const config::Projector& p : installation.projectors) ids.push_back(p.id);
  if (!options_.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(options_.out_dir) / "logs", ec);
    if (ec) return Error{"cannot create the output folder '" + options_.out_dir + "': " + ec.message()};
    const auto csv_path = std::filesystem::path(options_.out_dir) / "frames.csv";
    csv_.open(csv_path);
    if (!csv_) return Error{"cannot write " + csv_path.string()};
    csv_ << frames_csv_header();
  }
  recorder_.emplace(ids);
  // A replay (up to millions of samples) is moved, not copied, into the protocol.
  const std::size_t replay_samples = options_.run.replay.size();
  std::vector<tracking::ReplaySample> replay = std::move(options_.run.replay);
  RunSettings run = options_.run;
  run.replay = std::move(replay);
  run.send_clock = clock::monotonic_now;
  const std::optional<config::Tracking>& tracking = installation.viewer.tracking;
  if (tracking && !options_.out_dir.empty()) {
    const auto head_path = std::filesystem::path(options_.out_dir) / "head.csv";
    head_csv_.open(head_path);
    if (!head_csv_) return Error{"cannot write " + head_path.string()};
    head_csv_ << head_csv_header();
  }
  if (auto made = make_live_scene(run); !made) return made;
  protocol_.emplace(installation, options_.scene, std::move(run), *recorder_);
  // The journal's assets first: usable at once (no node is up yet), and in
  // every welcome.
  for (auto& [id, asset] : journal_assets_) carry_out(protocol_->add_asset(id, asset));
  journal_assets_.clear();
  if (session_port_) {
    session_port_->on_asset_loaded([this](const std::string& id, std::shared_ptr<const scene::LoadedScene> asset) {
      if (!finished_) carry_out(protocol_->add_asset(id, std::move(asset)));
    });
    session_port_->on_request_handled([this] {
      if (!finished_) carry_out(protocol_->scene_edited());
    });
  }

  // Listen.
  auto bound = listener_.listen(settings.listen, settings.port);
  if (!bound) return Error{"master.listen: " + bound.error()};
  port_ = bound.value();
  if (auto written = write_port_file(options_.port_file, port_, "port file"); !written) return written;
  log_.info("listening on {}:{}; waiting for {} node(s): {}", settings.listen, port_, ids.size(), util::joined(ids));
  if (tracking && tracking->source == config::TrackingSource::dtrack) {
    if (auto listening = listen_to_tracker(*tracking, settings.frame_rate); !listening) return listening;
  } else if (tracking) {
    log_.info("tracking: replaying {} ({} samples), predicted {}", tracking->file, replay_samples,
              config::to_string(tracking->prediction));
  }
  if (session_port_) {
    auto port = session_port_->start([this] { return protocol_->progress().next_frame; });
    if (!port) return Error{port.error()};
    log_.info("scene sessions on {}:{}: applications may place instances of '{}'", settings.api->listen, port.value(),
              options_.scene.definition.asset_id);
    if (auto written = write_port_file(options_.api_port_file, port.value(), "api port file"); !written) {
      return written;
    }
  }
  // After the session port: its WebSockets are opened through the status server.
  if (settings.status) {
    if (auto serving = start_status_service(*settings.status); !serving) return serving;
  }
  if (options_.run.secret) {
    log_.info("nodes must prove they hold the shared secret in {}", options_.secret_path);
  } else {
    log_.warn("no shared secret (master.secret_file): accepting nodes from this machine's loopback addresses only");
  }

  if (options_.local) {
    launcher_.emplace(options_.node_binary);
    for (const std::string& id : ids) {
      std::vector<std::string> args{
          "--master", "127.0.0.1:" + std::to_string(port_), "--id", id, "--log-level", options_.node_log_level};
      if (!options_.secret_path.empty()) {
        args.push_back("--secret-file");
        args.push_back(options_.secret_path);
      }
      if (!options_.out_dir.empty()) {
        args.push_back("--capture-dir");
        args.push_back((std::filesystem::path(options_.out_dir) / "nodes" / id).string());
      }
      args.insert(args.end(), options_.node_args.begin(), options_.node_args.end());
      auto pid = launcher_->spawn(id, args, node_log_path(id));
      if (!pid) return Error{"cannot start the node for projector '" + id + "': " + pid.error()};
      log_.debug("started node '{}' as pid {}", id, pid.value());
    }
  }

  signals_.async_wait([this](const boost::system::error_code& error, int signal) {
    if (!error) on_signal(signal);
  });
  listener_.start([this](asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback) {
    if (!finished_) on_accepted(std::move(socket), peer_text, loopback);
  });
  const clock::Nanos now = clock::monotonic_now();
  if (launcher_) carry_out(protocol_->local_nodes_running(launcher_->running(), now));
  carry_out(protocol_->start(now));
  housekeeping();
  return {};
}

Result<void> Master::start_status_service(const config::StatusServer& settings) {
  OperatorAccess access;
  access.reads_need_token = !config::is_loopback_address(settings.listen);
  if (options_.run.secret) access.token = net::status_token(*options_.run.secret);
  access.scene_sessions = session_port_.has_value();
  StatusService::SessionOpener open_session;
  if (session_port_) {
    open_session = [this](const std::string& application, const std::string& peer) {
      return session_port_->websocket(application, peer);
    };
  }
  // Asked on the server's thread, carried out on this one.
  auto on_command = [this](OperatorCommand command, const std::string& from) {
    asio::post(io_, [this, command, from] {
      if (!finished_) carry_out(protocol_->operator_command(command, from, clock::monotonic_now()));
    });
  };
  status_service_ = std::make_unique<StatusService>(settings, std::move(access), std::move(on_command),
                                                    std::move(open_session), log_);
  auto port = status_service_->start();
  if (!port) return Error{port.error()};
  std::string host = settings.listen.find(':') != std::string::npos ? "[" + settings.listen + "]" : settings.listen;
  log_.info("operator page on http://{}:{}/ (status.json, metrics); reads {}; controls {}", host, port.value(),
            config::is_loopback_address(settings.listen) ? "open on loopback" : "need the token",
            options_.run.secret ? "need the token (optique-master --print-status-token)"
                                : "off (no master.secret_file, so no token)");
  publish_status();  // before the port is told: a first request finds a status
  return write_port_file(options_.status_port_file, port.value(), "status port file");
}

void Master::publish_status() {
  if (!status_service_) return;
  const clock::Nanos now = clock::monotonic_now();
  last_published_ = now;
  LiveStatus status = protocol_->live(now);
  status.config_file = options_.config.path;
  status.uptime_s = static_cast<double>(now - started_) / 1e9;
  if (options_.warnings) status.warnings = last_warnings(*options_.warnings);
  status.clients = status_service_->clients();
  status_service_->publish(status);
}

// ---------------------------------------------------------------- connections

void Master::on_accepted(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback) {
  const PeerId id = next_peer_++;
  auto connection = net::Connection::create(std::move(socket), kMaxHelloBytes);
  connections_[id] = connection;
  connection->start({
      [this, id](wire::Envelope& message, clock::Nanos received) {
        carry_out(protocol_->message(id, message, received));
      },
      [this, id](const std::string& reason) {
        connections_.erase(id);
        carry_out(protocol_->closed(id, reason, clock::monotonic_now()));
      },
      {},  // a node's message over the size closes it
  });
  carry_out(protocol_->accepted(id, peer_text, loopback, net::random_nonce(), clock::monotonic_now()));
}

net::Connection* Master::connection(PeerId peer) {
  const auto found = connections_.find(peer);
  return found == connections_.end() || !found->second->is_open() ? nullptr : found->second.get();
}

// ---------------------------------------------------------------- actions

void Master::carry_out(Actions actions) {
  // Applications wait while a barrier round is under way (SessionPort::hold):
  // from before its FrameBegin goes out to after its Swap has.
  if (session_port_ && protocol_ && protocol_->in_round()) session_port_->hold(true);
  for (Action& action : actions) carry_out(action);
  if (session_port_ && protocol_) session_port_->hold(protocol_->in_round());
}

void Master::carry_out(Action& action) {
  std::visit(util::Overloaded{
                 [&](Send& a) {
                   net::Connection* c = connection(a.peer);
                   if (c == nullptr) return;
                   if (a.shared) {
                     if (a.shared != serialized_for_) {
                       serialized_.resize(a.shared->ByteSizeLong());
                       (void)a.shared->SerializeWithCachedSizesToArray(serialized_.data());
                       serialized_for_ = a.shared;
                     }
                     c->send_serialized(serialized_);
                     return;
                   }
                   // A pong's t3 is when it leaves: stamped as late as the master can.
                   if (a.message.has_pong()) a.message.mutable_pong()->set_t3(clock::monotonic_now());
                   c->send(a.message);
                 },
                 [&](Close& a) {
                   net::Connection* c = connection(a.peer);
                   if (c == nullptr) return;
                   if (a.after_sending) {
                     c->close_after_sending(a.reason);
                   } else {
                     c->close(a.reason);
                   }
                 },
                 [&](SetDeadline& a) {
                   if (net::Connection* c = connection(a.peer)) c->set_deadline(a.after, a.reason);
                 },
                 [&](CancelDeadline& a) {
                   if (net::Connection* c = connection(a.peer)) c->cancel_deadline();
                 },
                 [&](SetLiveness& a) {
                   if (net::Connection* c = connection(a.peer)) c->set_liveness_timeout(a.timeout, a.reason);
                 },
                 [&](SetMaxPayload& a) {
                   if (net::Connection* c = connection(a.peer)) c->set_max_payload_bytes(a.bytes);
                 },
                 [&](Protect& a) {
                   if (net::Connection* c = connection(a.peer)) c->protect(a.keys.to_node, a.keys.to_master, false);
                 },
                 [&](Arm& a) { arm(a.timer, a.at); },
                 [&](Disarm& a) {
                   ++timer_generations_[timer_slot(a.timer)];
                   timers_[timer_slot(a.timer)]->cancel();
                 },
                 [&](StopAccepting&) { listener_.close(); },
                 [&](SignalLocalNodes& a) {
                   if (launcher_) launcher_->signal_all(a.signal);
                 },
                 [&](HeadShown& a) {
                   if (head_csv_.is_open()) head_csv_ << head_csv_row(a);
                 },
                 [&](FrameRows& a) {
                   if (csv_.is_open()) csv_ << frames_csv(a.rows);
                 },
                 [&](Finish& a) { finish(a.exit_code); },
                 [&](Log& a) { log_.log(a.level, "{}", a.text); },
                 [&](AppEvent& a) {
                   if (session_port_) session_port_->publish(a.event);
                 },
                 // An asset from the journal is in the live scene already.
                 [&](AssetUsable& a) {
                   if (session_port_ && !live_->has_asset(a.asset)) session_port_->asset_usable(a);
                 },
                 [&](AssetFailed& a) {
                   if (session_port_) session_port_->asset_unusable(a.asset, a.reason);
                 },
             },
             action);
}

std::size_t Master::timer_slot(Timer timer) {
  const auto slot = static_cast<std::size_t>(timer);
  assert(slot < kTimers.size());  // every Timer is in kTimers (master/actions.h)
  return slot;
}

void Master::arm(Timer timer, clock::Nanos at) {
  asio::steady_timer& t = *timers_[timer_slot(timer)];
  t.expires_after(std::chrono::nanoseconds(std::max<clock::Nanos>(0, at - clock::monotonic_now())));
  // A timer that expired before it was disarmed or armed again still runs its
  // handler, with success: the generation tells it that it is stale.
  const std::uint64_t generation = ++timer_generations_[timer_slot(timer)];
  t.async_wait([this, timer, generation](const boost::system::error_code& error) {
    if (error || generation != timer_generations_[timer_slot(timer)]) return;
    carry_out(protocol_->timer(timer, clock::monotonic_now()));
  });
}

// ---------------------------------------------------------------- periodic

void Master::housekeeping() {
  if (finished_) return;
  if (launcher_) {
    for (const ChildExit& exit : launcher_->reap()) {
      const std::string log_hint = options_.out_dir.empty() ? std::string() : "; its log: " + node_log_path(exit.id);
      carry_out(protocol_->local_node_exited(exit.id, "(pid " + std::to_string(exit.pid) + ") " + exit.describe(),
                                             exit.clean(), log_hint, clock::monotonic_now()));
      if (finished_) return;
    }
    carry_out(protocol_->local_nodes_running(launcher_->running(), clock::monotonic_now()));
  }
  if (finished_) return;
  update_status();
  if (clock::monotonic_now() - last_published_ >= 200 * clock::kNanosPerMilli) publish_status();
  housekeeping_timer_.expires_after(milliseconds(100));
  housekeeping_timer_.async_wait([this](const boost::system::error_code& error) {
    if (!error) housekeeping();
  });
}

void Master::on_signal(int signal) {
  status_.clear();
  carry_out(protocol_->interrupted(strsignal(signal), clock::monotonic_now()));
  if (finished_) return;
  signals_.async_wait([this](const boost::system::error_code& error, int next) {
    if (!error) on_signal(next);
  });
}

void Master::update_status() {
  if (!status_.enabled()) return;
  const clock::Nanos now = clock::monotonic_now();
  if (now - last_status_ < 250 * clock::kNanosPerMilli) return;
  const MasterProtocol::Progress progress = protocol_->progress();
  const std::uint64_t frame = progress.next_frame;
  const double rate = last_status_ == 0
                          ? 0.0
                          : static_cast<double>(frame - status_frame_) * 1e9 / static_cast<double>(now - last_status_);
  last_status_ = now;
  status_frame_ = frame;
  const std::string total = options_.run.frames ? std::to_string(options_.run.frames) : std::string("-");
  const RunTotals& totals = recorder_->totals();
  const double shown_by_all = 100.0 * shown_by_all_share(totals.frames_finalized, totals.frames_with_missing_node);
  char line[240];
  std::snprintf(line, sizeof line,
                "frame %llu/%s  %.1f of %g Hz  nodes %zu/%zu  shown by all %.1f %%  skew %.0f us  missing %llu",
                static_cast<unsigned long long>(frame), total.c_str(), rate,
                options_.config.installation.master.frame_rate, progress.nodes_up, progress.projectors, shown_by_all,
                totals.last_present_skew_us, static_cast<unsigned long long>(totals.frames_with_missing_node));
  status_.show(line);
}

// ---------------------------------------------------------------- the end

void Master::finish(int exit_code) {
  if (finished_) return;
  finished_ = true;
  exit_code_ = exit_code;
  status_.clear();
  for (auto& timer : timers_) timer->cancel();
  housekeeping_timer_.cancel();
  signals_.cancel();
  listener_.close();
  if (session_port_) session_port_->close("the master is shutting down");
  boost::system::error_code ignored;
  if (tracker_receiver_) {
    tracker_receiver_->stop();
    carry_out(protocol_->tracker_input(tracker_receiver_->take()));  // the last counts, for run.json
  }
  tracker_socket_.close(ignored);
  if (launcher_) {
    for (const ChildExit& exit : launcher_->reap()) {
      log_.debug("node '{}' (pid {}) {}", exit.id, exit.pid, exit.describe());
    }
  }
  write_outputs();
  publish_status();  // the last word: done
  io_.stop();
}

void Master::write_outputs() {
  if (options_.out_dir.empty()) return;
  for (std::ofstream* csv : {&csv_, &head_csv_}) {
    if (csv->is_open()) csv->flush();
  }
  if (csv_.is_open() && !csv_) {
    log_.error("cannot write {}", (std::filesystem::path(options_.out_dir) / "frames.csv").string());
    exit_code_ = kExitFailed;
  }
  report::RunReport report = protocol_->report();
  report.set_config_file(options_.config.path);
  report.set_config_sha256(options_.config.sha256);
  const std::string json = report_json(report);
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

std::string Master::node_log_path(const std::string& id) const {
  if (options_.out_dir.empty()) return {};
  return (std::filesystem::path(options_.out_dir) / "logs" / (id + ".log")).string();
}

}  // namespace optique::master
