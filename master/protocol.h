#pragma once
// The master's side of the protocol, without sockets, timers or processes: it
// takes events (a connection accepted, a message, a connection closed, a timer
// due, a local node's exit, an interrupt) with the time they happened, and
// answers with actions for its shell (master/app/master.h) to carry out, in order:
// send, close, set a connection's deadline, arm a timer, stop accepting, signal
// the local nodes, finish, log. Every rule — admission and authentication, the
// frame loop and its barrier, stragglers, rejoining and resyncing, the lights'
// shares, shutting down — lives here and is tested in microseconds
// (tests/unit/test_master_protocol.cpp). By concern: the connections and the
// timers in protocol.cpp, the frame loop in frame_loop.cpp, stopping and the
// reports in run_control.cpp; serving the scene's files is a unit of its own
// (master/scene_server.h), as is the tracked head (master/viewer_head.h).

#include <spdlog/common.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "clock/clock.h"
#include "config/installation.h"
#include "master/actions.h"
#include "master/barrier.h"
#include "master/focus_schedule.h"
#include "master/live_status.h"
#include "master/navigation.h"
#include "master/operator_command.h"
#include "master/render_pace.h"
#include "master/run/exit_codes.h"
#include "master/run/scene_authority.h"
#include "master/run/stacked_groups.h"
#include "master/run_recorder.h"
#include "master/scene_server.h"
#include "master/session/journal.h"
#include "master/session/live_scene.h"
#include "master/viewer_head.h"
#include "net/auth.h"
#include "net/session_seal.h"
#include "optique/report.pb.h"
#include "optique/wire.pb.h"
#include "protocol/welcome.h"
#include "scene_load/load_scene.h"
#include "tracking/head_tracker.h"

namespace optique::master {

// The largest frame a peer may send before its hello is accepted.
inline constexpr std::uint32_t kMaxHelloBytes = 4096;
struct RunSettings {
  std::uint64_t frames = 0;         // 0: until interrupted
  std::uint64_t capture_every = 0;  // ask nodes to capture every K-th frame (0: never)
  // Nodes must prove they hold it; without one only loopback peers are accepted.
  std::optional<net::Secret> secret;
  // A `replay` tracker's samples (tracking/replay.h), loaded before the run:
  // fed at their times from the start.
  std::vector<tracking::ReplaySample> replay;
  // Reads the clock at the instant a FrameBegin goes out, once the frame's state
  // is computed: a barrier round is from then to the Swap, not the master's own
  // work on the frame. Unset (tests): the time of the event that began the frame.
  std::function<clock::Nanos()> send_clock;
  // The live scene applications edit (master/session/live_scene.h), which must
  // outlive the protocol: an edit made before frame k begins is in frame k.
  // None: the scene is a function of time alone.
  LiveScene* live = nullptr;
  // A recorded session played again into `live` (--replay): its transactions
  // of frame k applied as frame k begins. Must outlive the protocol.
  JournalReplay* journal_replay = nullptr;
};

class MasterProtocol {
 public:
  // Keeps references to all four; they must outlive it.
  MasterProtocol(const config::Installation& installation, const scene::LoadedScene& scene, RunSettings settings,
                 RunRecorder& recorder);

  // Times are the master's monotonic clock (clock::monotonic_now()), the
  // protocol's clock.
  [[nodiscard]] Actions start(clock::Nanos now);
  // A connection came from `peer_text` (loopback: from this machine); `nonce` is
  // fresh randomness for its challenge (net::random_nonce()).
  [[nodiscard]] Actions accepted(PeerId peer, const std::string& peer_text, bool loopback,
                                 const std::vector<std::uint8_t>& nonce, clock::Nanos now);
  [[nodiscard]] Actions message(PeerId peer, const wire::Envelope& message, clock::Nanos now);
  [[nodiscard]] Actions closed(PeerId peer, const std::string& reason, clock::Nanos now);
  [[nodiscard]] Actions timer(Timer timer, clock::Nanos now);
  // A local node process ended (`how`: "exited with status 2"; clean: status 0).
  [[nodiscard]] Actions local_node_exited(const std::string& id, const std::string& how, bool clean,
                                          const std::string& log_hint, clock::Nanos now);
  // How many local node processes are still running (after spawning, reaping).
  [[nodiscard]] Actions local_nodes_running(std::size_t count, clock::Nanos now);
  // SIGINT or SIGTERM: the first finishes the frame and shuts down in order, a
  // second stops at once.
  [[nodiscard]] Actions interrupted(const std::string& signal_name, clock::Nanos now);
  // What the head tracker's datagrams brought (viewer.tracking with source
  // dtrack), read and parsed off the frame loop (master/app/tracker_receiver.h).
  [[nodiscard]] Actions tracker_input(tracking::TrackerInput input);
  // The operator's page asked (`from`: who, for the log). Pause: no frame
  // begins after the one under way, whose picture stays on every projector;
  // the scene waits too. Resume: frames go on from where they stopped. Stop:
  // as a first interrupt, the run finishes in order.
  [[nodiscard]] Actions operator_command(OperatorCommand command, const std::string& from, clock::Nanos now);
  // An asset an application loaded (checked and hashed off the io thread),
  // named `id`: offered to every node that has said hello (and in every
  // welcome from now on); AssetUsable once every node in the frames has
  // readied it (at once when none is), AssetFailed when one cannot. A built-in
  // asset (no files) or an id offered before is a contract violation.
  [[nodiscard]] Actions add_asset(const std::string& id, std::shared_ptr<const scene::LoadedScene> asset);
  // An application changed the live scene: the instances it changed go to
  // every node now, or after the barrier round under way (master/staged_edits.cpp).
  [[nodiscard]] Actions scene_edited();

  // For the status line and tests: the frame to begin next, the nodes up of the
  // projectors, whether frames are running.
  struct Progress {
    std::uint64_t next_frame = 0;
    std::size_t nodes_up = 0;
    std::size_t projectors = 0;
    bool running = false;  // frames have started and the run is not draining
  };
  // A barrier round is under way: from the FrameBegin to the Swap.
  [[nodiscard]] bool in_round() const { return barrier_.active(); }
  [[nodiscard]] Progress progress() const {
    return {next_frame_, nodes_up(), slots_.size(), state_ == RunState::running};
  }
  // The run's summary (after Finish: every frame finalized).
  [[nodiscard]] report::RunReport report() const;
  // What the operator sees now; the shell adds uptime, warnings and clients.
  [[nodiscard]] LiveStatus live(clock::Nanos now) const;

 private:
  [[nodiscard]] std::size_t nodes_up() const;
  enum class Phase { handshake, configuring, joined, in_barrier, out_of_barrier };
  enum class RunState { starting, running, draining, closing, done };

  struct Session {
    std::string peer_text;
    std::optional<std::size_t> slot;
    Phase phase = Phase::handshake;
    std::vector<std::uint8_t> nonce;  // of its challenge
    bool refused = false;             // said so in the log already
    SceneServed scene;                // its scene's files, if it has no copy
    // The frame it was last told to draw and has not answered yet: out of the
    // barrier, it is told to skip frames until it answers, then draws the
    // newest and is waited for again.
    std::optional<std::uint64_t> drawing;
    clock::Nanos drawing_since = 0;  // when the master sent it that frame
    RenderPace pace;
    bool said_slow = false;              // logged once that it draws slower than the period
    std::set<std::string> assets_ready;  // readied (or in its welcome: ready once it is configured)
  };
  struct Slot {
    std::optional<PeerId> peer;
    std::optional<LightShare> sent_share;  // the share of the lights its node was last told
  };

  void on_hello(PeerId peer, Session& session, const wire::Envelope& message, clock::Nanos now, Actions& out);
  void on_configured(PeerId peer, Session& session, const wire::Configured& configured, clock::Nanos now, Actions& out);
  void on_ready(Session& session, const wire::FrameReady& ready, clock::Nanos received, clock::Nanos now, Actions& out);
  // Whether every node that is up is behind (out of the barrier, still drawing
  // an earlier frame): then a frame would be shown by nobody, and the next one
  // waits for the first of them to answer.
  [[nodiscard]] bool all_behind() const;
  void begin_if_held_frame_may(clock::Nanos now, Actions& out);
  void say_if_slow(Session& session, Actions& out);
  void on_presented(Session& session, const wire::Presented& presented, clock::Nanos now, Actions& out);
  // `slot` showed the last swapped frame, or is gone: the next frame may begin
  // once no node is still to show it.
  void present_owed(std::size_t slot, clock::Nanos now, Actions& out);
  void refuse(PeerId peer, Session& session, const std::string& node_id, const std::string& reason, bool retriable,
              Actions& out);
  void send_resync(PeerId peer, Actions& out) const;
  void stage_edits(Actions& out);
  // The live scene's instances `ids`, as frame `frame` shows them, into
  // current_state_ (and its instances' hash): what changed, as a delta.
  [[nodiscard]] wire::StateDelta take_live_instances(const std::set<std::string>& ids, std::uint64_t frame);

  void start_frames(clock::Nanos now, Actions& out);
  void begin_frame(clock::Nanos now, Actions& out);
  [[nodiscard]] wire::Envelope next_frame_begin(std::uint64_t frame, clock::Nanos display, bool captured,
                                                clock::Nanos now, Actions& out);
  [[nodiscard]] bool send_frame_begin(std::size_t slot, const std::shared_ptr<const wire::Envelope>& envelope,
                                      clock::Nanos now, clock::Nanos display, Actions& out);
  void wait_for(std::uint64_t frame, std::vector<std::size_t> waited, bool captured, clock::Nanos now, Actions& out);
  void on_barrier_timeout(clock::Nanos now, Actions& out);
  void swap(clock::Nanos now, Actions& out);
  void drain(const std::string& reason, clock::Nanos now, Actions& out);
  void wait_for_last_presents(bool frames_ran, clock::Nanos now, Actions& out);
  void say_goodbye(clock::Nanos now, Actions& out);
  void fail(const std::string& reason, clock::Nanos now, Actions& out);
  void finish_if_all_gone(Actions& out);
  void finish(Actions& out);

  // Shares automatic groups' lights among the nodes that are up (a node came or
  // went: `force`); the changes go out with the next FrameBegin.
  // Assets applications loaded (live_assets.cpp).
  void on_asset_ready(Session& session, const wire::AssetReady& ready, Actions& out);
  // Every asset not yet usable that every node in the frames has readied is now.
  void check_assets(Actions& out);
  [[nodiscard]] std::vector<protocol::AssetOffer> asset_offers() const;

  void rebalance_lights(bool force);
  void log_light_switches(std::uint64_t frame, const wire::StateDelta& delta, Actions& out) const;
  // Events for the scene session's subscribers (AppEvent), raised only with a live scene.
  void notify_frame(std::uint64_t frame, clock::Nanos display, const scene::SceneState& state, bool tracked,
                    Actions& out) const;
  void notify_run(session::RunChanged::State run, const std::string& reason, Actions& out) const;
  void notify_node(std::size_t slot, bool up, const std::string& reason, Actions& out) const;
  [[nodiscard]] bool up(const Slot& slot) const;  // through the handshake and configured
  // The projectors whose node has said hello and is setting up (GL, scene, shaders).
  [[nodiscard]] std::vector<std::size_t> slots_configuring() const;
  [[nodiscard]] std::string slot_id(std::size_t slot) const;
  [[nodiscard]] Session* session_of(std::size_t slot);
  [[nodiscard]] const Session* session_of(std::size_t slot) const;

  const config::Installation& installation_;
  const config::MasterSettings& config_;
  const scene::LoadedScene& scene_;
  RunSettings settings_;
  RunRecorder& recorder_;

  std::map<PeerId, Session> sessions_;
  struct LiveAsset {
    protocol::AssetOffer offer;
    std::shared_ptr<const scene::LoadedScene> scene;
    bool usable = false;
  };
  std::vector<LiveAsset> assets_;  // in the order they were loaded
  std::vector<Slot> slots_;
  SceneAuthority authority_;
  SceneServer scene_server_;
  LightPlan light_plan_;
  std::optional<FocusSchedule> focus_;
  std::optional<ViewerHead> head_;  // viewer.tracking
  ViewerNavigation navigation_;     // flysticks, and what applications set
  // The state of the last frame begun, with the edits staged since
  // (stage_edits): what every node in the frames has.
  scene::SceneState current_state_;
  std::uint64_t current_hash_ = 0;               // of the last frame begun, as it began
  scene::InstancesHash current_instances_hash_;  // of current_state_'s instances, kept as they change
  Barrier barrier_;
  std::vector<std::size_t> ready_for_swap_;
  // The nodes told to show the last swapped frame that have not said they did.
  // Behind schedule, the next frame waits for them (up to a period after the
  // deadline, when they would no longer show it): its drawing on a shared
  // machine (local nodes, llvmpipe) would delay their presents. On schedule the
  // next frame's time comes after their presents anyway.
  std::vector<std::size_t> presents_owed_;
  std::uint64_t presents_owed_frame_ = 0;
  clock::Nanos presents_grace_end_ = 0;
  bool begin_when_presented_ = false;   // the next frame's time came while presents were owed
  bool begin_when_answered_ = false;    // the next frame's time came while every node was behind
  clock::Nanos barrier_allowance_ = 0;  // how long the frame in the barrier is waited for

  std::uint64_t next_frame_ = 0;
  clock::Nanos frame_period_ = 0;
  clock::Nanos schedule_origin_ = 0;
  std::uint64_t schedule_origin_frame_ = 0;

  RunState state_ = RunState::starting;
  // The startup timeout passed while nodes were still configuring: the frames
  // start once each of those is up or gone.
  bool startup_passed_ = false;
  bool terminating_ = false;      // goodbye's grace is over: SIGTERM sent, SIGKILL next
  bool paused_ = false;           // by the operator
  bool begin_on_resume_ = false;  // a frame's time came while paused
  std::string stopped_because_;
  std::uint64_t refused_connections_ = 0;
  std::size_t local_running_ = 0;
  int interrupts_ = 0;
  int exit_code_ = kExitOk;
};

}  // namespace optique::master
