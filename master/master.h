#pragma once
// The master: owns the scene and the clock, accepts nodes, and steps them through
// frames in lock-step (FrameBegin → FrameReady from every live node → Swap with a
// present deadline → Presented). One io_context thread; every wait is a timer.

#include <spdlog/logger.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/load.h"
#include "master/barrier.h"
#include "master/exit_codes.h"
#include "master/focus_schedule.h"
#include "master/local_launcher.h"
#include "master/run_recorder.h"
#include "master/scene_authority.h"
#include "master/stacked_groups.h"
#include "master/status_line.h"
#include "net/auth.h"
#include "net/connection.h"
#include "scene/load_scene.h"
#include "util/result.h"

namespace optique::master {

namespace asio = boost::asio;

struct MasterOptions {
  config::LoadedConfig config;
  scene::LoadedScene scene;  // loaded before anything starts, so a bad scene starts nothing
  std::uint64_t frames = 0;  // 0: until interrupted
  std::string out_dir;       // empty: write no files
  bool local = false;        // start one node process per projector here
  std::string node_binary;
  std::vector<std::string> node_args;  // extra arguments for local nodes
  std::string port_file;               // write the bound port here once listening
  std::string node_log_level = "info";
  std::uint64_t capture_every = 0;  // ask nodes to capture every K-th frame (0: never)
  bool status_line = false;
  // Nodes must prove they hold it; without one only loopback peers are accepted.
  std::optional<net::Secret> secret;
  std::string secret_path;  // handed to local nodes
};

// The largest frame a peer may send before its hello is accepted.
inline constexpr std::uint32_t kMaxHelloBytes = 4096;
// How long a node may take to set itself up (GL context, scene) after the welcome.
inline constexpr std::chrono::seconds kConfigureTimeout{30};

class Master {
 public:
  Master(asio::io_context& io, MasterOptions options, spdlog::logger& log);
  ~Master();
  Master(const Master&) = delete;
  Master& operator=(const Master&) = delete;

  // Listens, starts local nodes, and schedules everything; then run the io_context.
  [[nodiscard]] Result<void> start();
  [[nodiscard]] int exit_code() const { return exit_code_; }

 private:
  enum class Phase { handshake, configuring, joined, in_barrier, out_of_barrier };
  enum class RunState { starting, running, draining, closing, done };

  struct Session {
    std::shared_ptr<net::Connection> connection;
    std::optional<std::size_t> slot;
    Phase phase = Phase::handshake;
    std::vector<std::uint8_t> nonce;  // of its challenge
    bool refused = false;             // said so in the log already
  };

  struct Slot {
    const config::Projector* projector = nullptr;
    std::shared_ptr<Session> session;
    std::optional<LightShare> sent_share;  // the share of the lights its node was last told
  };

  void accept_next();
  void on_connection(asio::ip::tcp::socket socket);
  void on_message(const std::shared_ptr<Session>& session, wire::Envelope& message);
  void on_closed(const std::shared_ptr<Session>& session, const std::string& reason);
  void handle_hello(const std::shared_ptr<Session>& session, wire::Envelope& message);
  void handle_configured(Session& session, const wire::Configured& configured);
  void send_resync(Session& session);
  void refuse(Session& session, const std::string& node_id, const std::string& reason, bool retriable);
  void handle_ready(Session& session, const wire::FrameReady& ready, clock::Nanos received);
  void handle_presented(Session& session, const wire::Presented& presented);

  void start_frames();
  void begin_frame();
  void swap();
  void on_barrier_timeout();
  void schedule_next_frame(clock::Nanos now);

  void drain(const std::string& reason);
  void wait_for_last_presents(bool frames_ran);
  void say_goodbye();
  void finish();
  void fail(const std::string& reason);

  // Shares automatic groups' lights among the nodes that are up (a node came or
  // went: `force`); the changes go out with the next FrameBegin.
  void rebalance_lights(bool force);
  void log_light_switches(std::uint64_t frame, const wire::StateDelta& delta, const scene::SceneState& state);
  void housekeeping();
  void send_heartbeats();
  void on_signal(int signal);
  void update_status();
  void write_outputs();

  [[nodiscard]] std::size_t nodes_up() const;
  [[nodiscard]] std::string slot_id(std::size_t slot) const;
  // Where a local node's output goes (empty without --out).
  [[nodiscard]] std::string node_log_path(const std::string& id) const;

  asio::io_context& io_;
  MasterOptions options_;
  spdlog::logger& log_;
  const config::MasterSettings& settings_;

  asio::ip::tcp::acceptor acceptor_;
  asio::steady_timer accept_retry_timer_;
  bool accept_failing_ = false;
  std::uint64_t refused_connections_ = 0;  // never through the handshake: each logged once with its peer
  asio::signal_set signals_;
  asio::steady_timer frame_timer_;
  asio::steady_timer barrier_timer_;
  asio::steady_timer phase_timer_;  // startup wait, drain, goodbye: one at a time
  asio::steady_timer housekeeping_timer_;
  asio::steady_timer heartbeat_timer_;

  std::vector<Slot> slots_;
  std::vector<std::shared_ptr<Session>> sessions_;
  std::optional<SceneAuthority> authority_;
  std::optional<LightPlan> light_plan_;
  std::optional<FocusSchedule> focus_;
  scene::SceneState current_state_;
  std::uint64_t current_hash_ = 0;
  Barrier barrier_;
  std::vector<std::size_t> ready_for_swap_;

  std::uint64_t next_frame_ = 0;
  clock::Nanos frame_period_ = 0;
  clock::Nanos schedule_origin_ = 0;
  std::uint64_t schedule_origin_frame_ = 0;

  std::ofstream csv_;
  std::optional<RunRecorder> recorder_;
  std::optional<LocalLauncher> launcher_;
  StatusLine status_;
  clock::Nanos last_status_ = 0;
  std::uint64_t status_frame_ = 0;
  RunState state_ = RunState::starting;
  std::string stopped_because_;
  std::uint16_t port_ = 0;
  int exit_code_ = kExitOk;
  int interrupts_ = 0;
};

}  // namespace optique::master
