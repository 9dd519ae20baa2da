#pragma once
// The master's shell: the listening socket and its connections, timers, signals,
// the local node processes, the status line and the output files, around the
// IO-free MasterProtocol (master/protocol.h), which decides everything. Each
// socket event, timer, child exit or signal becomes one call of the protocol;
// its actions are carried out here, in order. One io_context thread.

#include <spdlog/logger.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include <array>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/load.h"
#include "master/app/local_launcher.h"
#include "master/app/session_port.h"
#include "master/app/status_line.h"
#include "master/app/tcp_listener.h"
#include "master/app/tracker_receiver.h"
#include "master/protocol.h"
#include "master/run/exit_codes.h"
#include "master/run_recorder.h"
#include "master/status/status_service.h"
#include "net/auth.h"
#include "net/connection.h"
#include "scene_load/load_scene.h"
#include "util/result.h"

namespace optique::master {

namespace asio = boost::asio;

struct MasterOptions {
  config::LoadedConfig config;
  scene::LoadedScene scene;  // loaded before anything starts, so a bad scene starts nothing
  RunSettings run;           // frames, captures, the shared secret
  std::string out_dir;       // empty: write no files
  bool local = false;        // start one node process per projector here
  std::string node_binary;
  std::vector<std::string> node_args;  // extra arguments for local nodes
  std::string port_file;               // write the bound port here once listening
  std::string node_log_level = "info";
  bool status_line = false;
  std::string secret_path;  // handed to local nodes
  // The log's last warnings, for the status page (make_warning_sink(), added to
  // the logger by whoever made it); none: the page lists none.
  std::shared_ptr<WarningSink> warnings;
  std::string status_port_file;  // write the status server's port once listening
  std::string api_port_file;     // write the scene session's port (master.api) once listening
  std::string record_path;       // journal the live scene's transactions here (restored from it first)
  std::string replay_path;       // play the last run of this journal again
};

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
  // The head tracker's datagrams (viewer.tracking, source dtrack), read on
  // their own thread; what they brought taken on this one.
  [[nodiscard]] Result<void> listen_to_tracker(const config::Tracking& tracking, double frame_rate);
  void take_tracker_input();
  void on_accepted(asio::ip::tcp::socket socket, const std::string& peer_text, bool loopback);
  void carry_out(Actions actions);
  void carry_out(Action& action);
  void arm(Timer timer, clock::Nanos at);
  [[nodiscard]] static std::size_t timer_slot(Timer timer);  // its steady_timer's index
  void housekeeping();
  void on_signal(int signal);
  void update_status();
  [[nodiscard]] Result<void> start_status_service(const config::StatusServer& settings);
  // The live scene, with master.api or --replay: its journal restored or
  // replayed, its session port made (not yet listening).
  [[nodiscard]] Result<void> make_live_scene(RunSettings& run);
  // Loads every asset of `journal` again, checks each is what was loaded then,
  // and adds it to the live scene.
  [[nodiscard]] Result<void> load_journal_assets(const Journal& journal);
  void publish_status();
  void finish(int exit_code);
  void write_outputs();
  // Where a local node's output goes (empty without --out).
  [[nodiscard]] std::string node_log_path(const std::string& id) const;
  [[nodiscard]] net::Connection* connection(PeerId peer);

  asio::io_context& io_;
  MasterOptions options_;
  spdlog::logger& log_;
  // The last message sent to several peers (Send::shared), serialized once:
  // held so that its bytes are those of that very message.
  std::shared_ptr<const wire::Envelope> serialized_for_;
  std::vector<std::uint8_t> serialized_;

  std::ofstream csv_;
  std::ofstream head_csv_;  // the head shown each frame, with tracking
  std::optional<RunRecorder> recorder_;
  std::optional<LiveScene> live_;                // outlives the session port and the protocol
  std::optional<JournalReplay> journal_replay_;  // --replay
  // The assets of the journal (--record, --replay), loaded and checked before
  // the protocol is made, for it to offer.
  std::vector<std::pair<std::string, std::shared_ptr<const scene::LoadedScene>>> journal_assets_;
  std::optional<SessionPort> session_port_;  // master.api
  std::optional<MasterProtocol> protocol_;

  TcpListener listener_;  // the nodes'
  asio::ip::udp::socket tracker_socket_;
  std::unique_ptr<TrackerReceiver> tracker_receiver_;  // reads tracker_socket_: stopped before it closes
  asio::signal_set signals_;
  std::array<std::unique_ptr<asio::steady_timer>, kTimers.size()> timers_;  // one per Timer
  std::array<std::uint64_t, kTimers.size()> timer_generations_{};           // each arm or disarm: the one pending
  asio::steady_timer housekeeping_timer_;
  std::map<PeerId, std::shared_ptr<net::Connection>> connections_;
  PeerId next_peer_ = 1;

  std::optional<LocalLauncher> launcher_;
  std::unique_ptr<StatusService> status_service_;  // master.status
  clock::Nanos started_ = 0;
  clock::Nanos last_published_ = 0;
  StatusLine status_;
  clock::Nanos last_status_ = 0;
  std::uint64_t status_frame_ = 0;
  std::uint16_t port_ = 0;
  bool finished_ = false;
  int exit_code_ = kExitOk;
};

}  // namespace optique::master
