#pragma once
// The node's side of the protocol, without sockets, timers or GL: it takes events
// (connected, a message, closed, a signal, a timer run out, the answer to an
// action: configured, rendered, presented, the cache's) with the time they
// happened, and answers with actions for its shell (node/node.h) to carry out,
// in order: send, close, arm a deadline, render, present at, reconnect, stop, log.
// So every rule — the handshake, joining and rejoining, applying the state,
// which frames are shown and when, the clock estimate, giving up — is tested in
// microseconds (tests/unit/test_node_protocol.cpp).

#include <spdlog/common.h>

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "clock/clock.h"
#include "clock/offset_estimator.h"
#include "net/auth.h"
#include "net/envelope.h"
#include "net/session_seal.h"
#include "node/renderer.h"
#include "optique/wire.pb.h"
#include "protocol/frame_message.h"
#include "protocol/scene_fetch.h"
#include "protocol/welcome.h"
#include "scene/state.h"
#include "util/result.h"

namespace optique::node {

inline constexpr int kExitOk = 0;
inline constexpr int kExitRefused = 2;   // refused by the master, or bad command line
inline constexpr int kExitNoMaster = 3;  // gave up reaching the master

// Faults a test asks a node to show, so that the master's handling of them can
// be seen: all off by default, set only by hidden command-line options. They
// stay in the core, where the state they spoil is: the unit tests and the
// simulated cluster drive the core without a shell, and see the same faults.
struct NodeFaults {
  std::uint32_t protocol_version = net::kProtocolVersion;  // speak another version
  // Show the content of this many frames ago, as a node out of step with its
  // stacked partners would (reported in Presented.content_frame_id).
  std::uint32_t lag_frames = 0;
  // Nudge the scene state at this frame, as a bit flip or a bug would, to see
  // the master notice and repair it (0: never).
  std::uint64_t corrupt_state_at_frame = 0;
};

struct NodeSettings {
  std::string master;  // HOST:PORT, for messages
  std::string id;
  std::chrono::milliseconds give_up_after{10000};  // master unreachable this long: stop
  std::optional<net::Secret> secret;               // proves to the master this node belongs
  clock::LocalClock clock;                         // a skewed clock, in tests
  NodeFaults faults;
  // When the master is lost: show black (a frozen wall looks like a fault in the
  // show), or keep the last frame.
  bool hold_last_frame = false;
  // The renderer draws the scene, so a glTF scene's files must be on this
  // machine: from the cache, or fetched from the master (the null renderer: no).
  bool needs_scene_files = true;
  // The largest scene (all its files) this node fetches.
  std::uint64_t most_scene_bytes = std::uint64_t{8} << 30;
};

// --- actions

struct Send {
  wire::Envelope message;
};
struct Close {
  std::string reason;
  bool after_sending = false;  // let what is queued (a goodbye) go first
};
// A one-shot deadline on the connection: it closes with `reason` unless cancelled.
struct SetDeadline {
  std::chrono::milliseconds after{0};
  std::string reason;
};
struct CancelDeadline {};
// The hello is sent: from now on everything to the master is sealed with `send`
// and everything from it must open with `receive` (its first answer may be an
// unsealed refusal: a master that could not check this node's secret).
struct Protect {
  net::SessionKey send{};
  net::SessionKey receive{};
};
// The connection closes with `reason` when nothing arrives for `timeout`.
struct SetLiveness {
  std::chrono::milliseconds timeout{0};
  std::string reason;
};
// Set the renderer up for the job; answer Configured.
struct Configure {
  protocol::NodeJob job;
};
// Draw the frame; answer FrameRendered. The frame's state lives in the core
// until the next event.
struct Render {
  FrameInput frame;
};
// The master says this node is behind: keep what the frame carries, draw
// nothing, answer nothing (Renderer::skip).
struct Skip {
  FrameInput frame;
};
// Wait, without holding up other events, until the monotonic time `deadline`;
// then tell due(Due::present).
struct PresentAt {
  std::uint64_t frame_id = 0;
  clock::Nanos deadline = 0;
};
// Show image `image` of the rendered frame now; answer ImagePresented. A
// projector that shows two images per frame (a stereo one used as mono) shows
// the second half a frame after the first.
struct Present {
  int image = 0;
};
struct ShowBlack {};
// Tell due(Due::ping) after `after`.
struct PingIn {
  std::chrono::milliseconds after{0};
};
struct CancelPings {};
struct Reconnect {
  std::chrono::milliseconds after{0};
};
struct Stop {
  int exit_code = kExitOk;
};
struct Log {
  spdlog::level::level_enum level = spdlog::level::info;
  std::string text;
};
// The scene's files (node/scene_cache.h): answer SceneFound with the glTF's
// path when a whole copy is here; SceneFetchedElsewhere when another node of
// this host is fetching it into the same cache (unless `wait_for_others` is
// false); else start a new copy and answer SceneCopyStarted.
struct PrepareScene {
  scene::SceneManifest manifest;
  std::string sha256;
  bool wait_for_others = true;
};
// Waiting for another node's copy of the scene: look again after `after`, with
// due(Due::scene_recheck).
struct RecheckScene {
  std::chrono::milliseconds after{0};
};
// Write a chunk (checked against the manifest) into the copy; answer only a
// failure, SceneStoreFailed.
struct StoreSceneChunk {
  std::uint32_t file = 0;
  std::uint64_t offset = 0;
  std::string data;
};
// Every chunk is stored: check the copy whole, put it in place and answer
// SceneCopyFinished.
struct FinishScene {};
// The copy cannot be kept (the cache could not write it): remove it. A copy
// whose connection went, or whose node stops, is kept: it goes on after the
// reconnect, or in the next node to fetch the scene.
struct AbandonScene {};
// An asset offered while frames go on is here (its files at `asset.path`):
// give it to the renderer (Renderer::add_asset); answer AssetLoaded.
struct ReadyAsset {
  protocol::AssetOffer asset;
};

using Action = std::variant<Send, Close, SetDeadline, CancelDeadline, Protect, SetLiveness, Configure, Render, Skip,
                            PresentAt, Present, ShowBlack, PingIn, CancelPings, Reconnect, Stop, Log, PrepareScene,
                            RecheckScene, StoreSceneChunk, FinishScene, AbandonScene, ReadyAsset>;
using Actions = std::vector<Action>;

// --- answers: what the shell reports after carrying out an action that asks
// for one. The shell gives them to answer() after the list the action was in,
// in the order they came (node/node.cpp).

// To Configure.
struct Configured {
  Result<void> result;
  std::string renderer;  // what draws, for the logs
  WarmUp warm_up;        // how long the renderer's warm-up frame took
};
// To PrepareScene: a whole copy of the scene is here.
struct SceneFound {
  std::string gltf_path;
};
// To PrepareScene: another node of this host is fetching it into the same
// cache; its copy holds `bytes_there` so far.
struct SceneFetchedElsewhere {
  std::uint64_t bytes_there = 0;
};
// To PrepareScene: a copy is started; `started` says which chunks it already
// holds (one going on after a lost connection).
struct SceneCopyStarted {
  Result<protocol::SceneFetch::Present> started;
};
// To StoreSceneChunk, only when it failed.
struct SceneStoreFailed {
  std::string error;
};
// To FinishScene: the copy is in place, or why not.
struct SceneCopyFinished {
  Result<std::string> gltf_path;
};
// To Render.
struct FrameRendered {
  std::uint64_t frame_id = 0;
  clock::Nanos render_time = 0;
  Rendered how;
};
// To Present: the image is shown (at the answer's time).
struct ImagePresented {};
// To ReadyAsset: the renderer has it, or why not.
struct AssetLoaded {
  std::string asset;
  Result<void> result;
};

using Answer = std::variant<Configured, SceneFound, SceneFetchedElsewhere, SceneCopyStarted, SceneStoreFailed,
                            SceneCopyFinished, FrameRendered, ImagePresented, AssetLoaded>;

// The shell's timers, armed by PingIn, PresentAt and RecheckScene.
enum class Due { ping, present, scene_recheck };

class NodeProtocol {
 public:
  // How long the handshake and the state may take to arrive.
  static constexpr std::chrono::milliseconds kHandshakeTimeout{5000};
  static constexpr std::chrono::milliseconds kFirstBackoff{100};
  static constexpr std::chrono::milliseconds kMaxBackoff{2000};
  static constexpr int kPingBurst = 8;  // pings 5 ms apart on joining: an offset before the first swap
  static constexpr std::chrono::milliseconds kBurstInterval{5};
  // Forty a second: several samples in each 200 ms bucket of the drift fit, so
  // that its quietest is really quiet (the skewed-clock test's worst error fell
  // from 42 to 14 µs going from ten a second to forty).
  static constexpr std::chrono::milliseconds kPingInterval{25};
  // A ping that falls due during a frame's round (from a millisecond before the
  // next FrameBegin is expected until this node has presented) waits until the
  // round is over, at most this long: the master answers it outside its barrier,
  // so pings do not lengthen rounds (at forty a second they put the 8-node round
  // p99 up by 15-25 % when sent whenever due).
  static constexpr std::chrono::milliseconds kPingDeferral{10};
  static constexpr std::chrono::microseconds kRoundGuard{1000};
  // A scene being fetched: no chunk for this long and the connection is given up.
  static constexpr std::chrono::milliseconds kSceneStall{10000};
  // Another node of this host fetching the scene into the shared cache: its
  // copy is looked at this often, and the master told this often that this
  // node still waits (SceneWait). A copy that has not grown for kSceneStall
  // is not waited for any longer: this node fetches the scene itself.
  static constexpr std::chrono::milliseconds kSceneRecheck{200};
  static constexpr std::chrono::milliseconds kSceneWaitWord{1000};

  explicit NodeProtocol(NodeSettings settings);

  // Times are this machine's monotonic clock (clock::monotonic_now()).
  // `nonce`: fresh randomness for this connection's session keys
  // (net::random_nonce()); needed when the node has a secret.
  [[nodiscard]] Actions connected(clock::Nanos now, std::vector<std::uint8_t> nonce = {});
  [[nodiscard]] Actions connect_failed(const std::string& reason, clock::Nanos now);
  [[nodiscard]] Actions message(const wire::Envelope& message, clock::Nanos now);
  [[nodiscard]] Actions closed(const std::string& reason, clock::Nanos now);
  // The answer to an action, at `now` (for ImagePresented: when it was shown).
  [[nodiscard]] Actions answer(Answer answer, clock::Nanos now);
  // A timer the core armed has run out.
  [[nodiscard]] Actions due(Due timer, clock::Nanos now);
  // SIGINT or SIGTERM: say goodbye and stop.
  [[nodiscard]] Actions interrupted(const std::string& signal_name);

  [[nodiscard]] bool stopped() const { return phase_ == Phase::stopped; }
  [[nodiscard]] bool joined() const { return phase_ == Phase::joined; }
  [[nodiscard]] const scene::SceneState& state() const { return state_; }
  [[nodiscard]] const clock::OffsetEstimator& estimator() const { return estimator_; }

 private:
  enum class Phase {
    disconnected,
    awaiting_challenge,
    awaiting_welcome,
    preparing_scene,  // the shell looks for the scene's files, or starts a copy
    fetching_scene,   // chunks of the scene's files come from the master
    configuring,
    awaiting_state,
    joined,
    stopped
  };

  [[nodiscard]] static bool accepts(Phase phase, wire::Envelope::BodyCase kind);
  [[nodiscard]] bool accepts(const wire::Envelope& message) const;
  void on_configured(const Configured& answer, Actions& out);
  void on_scene_found(const SceneFound& answer, Actions& out);
  void on_scene_fetched_elsewhere(const SceneFetchedElsewhere& answer, clock::Nanos now, Actions& out);
  void on_scene_recheck_due(Actions& out);
  void on_scene_copy_started(const SceneCopyStarted& answer, clock::Nanos now, Actions& out);
  void on_scene_store_failed(const SceneStoreFailed& answer, Actions& out);
  void on_scene_copy_finished(const SceneCopyFinished& answer, clock::Nanos now, Actions& out);
  // The files of the scene or of an asset are here (at `path`).
  void fetched(const std::string& path, Actions& out);
  // Setting up: fetches the next of the job's files not yet here (the scene's,
  // then each asset's); when none is left, configures.
  void prepare_next(Actions& out);
  // Starts fetching `target`'s files: looks in the cache first.
  struct FetchTarget;
  void prepare(FetchTarget target, Actions& out);
  // The step of a fetch the shell's answer is for: `stage`, and the phase that
  // goes with it (the frames, for an asset offered while they go on).
  [[nodiscard]] bool fetch_at(Phase stage) const;
  void set_fetch_stage(Phase stage);
  // Assets offered while frames go on (asset_readying.cpp).
  void on_asset_offer(const wire::AssetOffer& offer, Actions& out);
  // In the frames: readies the next asset offered, if none is being readied.
  void ready_next(Actions& out);
  void on_asset_loaded(const AssetLoaded& answer, Actions& out);
  // Tells the master whether the asset being readied is ready, and goes on
  // with the next.
  void asset_done(const std::string& problem, Actions& out);
  void on_rendered(const FrameRendered& answer, Actions& out);
  void on_ping_due(clock::Nanos now, Actions& out);
  void on_present_due(clock::Nanos now, Actions& out);
  void on_presented(clock::Nanos now, Actions& out);
  void on_challenge(const wire::Envelope& message, Actions& out);
  void on_welcome(const wire::Welcome& welcome, Actions& out);
  void on_scene_chunk(const wire::SceneChunk& chunk, Actions& out);
  // The scene's files are here (or none are needed): set the renderer up.
  void configure(Actions& out);
  void cache_failed(const std::string& error, Actions& out);
  void on_resync(const wire::Resync& resync, clock::Nanos now, Actions& out);
  void on_staged_edit(const wire::StagedEdit& staged, Actions& out);
  void on_frame_begin(const wire::FrameBegin& begin, clock::Nanos now, Actions& out);
  void on_swap(const wire::FrameSwap& swap, clock::Nanos now, Actions& out);
  void on_pong(const wire::Pong& pong, clock::Nanos now, Actions& out);
  void send_ping(clock::Nanos now, Actions& out);
  // Between FrameBegin and presenting, or about to be.
  [[nodiscard]] bool in_round(clock::Nanos now) const;
  // The frame is shown or given up: a ping held back goes now.
  void end_round(clock::Nanos now, Actions& out);
  // Held up past the next frame's time (the process was stopped, the machine
  // stalled): showing it would put an old frame beside its partners' new one.
  [[nodiscard]] bool stale(clock::Nanos now, Actions& out) const;
  // The pending frame's next image (a projector that shows two per frame), its
  // share of the frame later; false when it was the last.
  [[nodiscard]] bool next_image();
  // Waits for the pending image's deadline; a stale one gives way to the frame's
  // next image, and a frame with none left ends its round.
  void wait_for_pending(clock::Nanos now, Actions& out);
  // The pending image was shown or given up.
  void image_done(clock::Nanos now, Actions& out);
  void release_held(clock::Nanos now, Actions& out);
  void stop(int exit_code, const std::string& reason, Actions& out);
  void log(Actions& out, spdlog::level::level_enum level, std::string text) const;

  NodeSettings settings_;
  Phase phase_ = Phase::disconnected;
  bool connection_open_ = false;
  std::vector<std::uint8_t> nonce_;  // this connection's, for the session keys
  std::optional<protocol::NodeJob> job_;
  std::optional<protocol::SceneFetch> fetch_;  // the scene's files coming from the master
  // What is being fetched: the scene's files or an asset's, while setting up
  // or (an asset offered then) while frames go on.
  struct FetchTarget {
    std::string name;    // for the log: "the scene", "the asset 'duck'"
    std::string detail;  // after the name, where it says what is fetched: " x.gltf"
    scene::SceneManifest files;
    std::string sha256;
    std::string* path = nullptr;  // where the copy's path goes (in job_ or readying_)
    bool in_frames = false;
    Phase stage = Phase::preparing_scene;  // preparing_scene or fetching_scene
  };
  std::optional<FetchTarget> target_;
  std::deque<protocol::AssetOffer> offers_;       // offered while frames go on, not yet readied
  std::optional<protocol::AssetOffer> readying_;  // the one being readied
  bool copy_unfinished_ = false;                  // a copy started and not yet put in place
  clock::Nanos fetch_started_ = 0;
  std::uint64_t fetch_had_bytes_ = 0;  // here already when the fetch (re)started
  int fetch_quarters_logged_ = 0;
  // Waiting for another node of this host to fetch the scene into the cache.
  struct SceneWaiting {
    clock::Nanos since = 0;
    clock::Nanos grew_at = 0;             // when its copy last grew
    std::optional<clock::Nanos> told_at;  // when the master was last told
    std::uint64_t bytes = 0;
  };
  std::optional<SceneWaiting> waiting_;
  scene::SceneState state_;
  scene::InstancesHash instances_hash_;  // of state_'s instances, kept as deltas change them
  // The lag hook's memory: the last lag_frames + 1 frames as they came.
  struct PastFrame {
    protocol::FrameMessage frame;
    scene::SceneState state;
  };
  std::deque<PastFrame> past_frames_;
  // The scene a later frame will show, sent ahead (a node that interpolates).
  std::optional<scene::SceneState> ahead_;
  std::optional<protocol::LightShare> share_;  // a new share that the frame being rendered starts
  std::optional<FrameInput> rendering_;        // between Render and rendered()
  bool skipping_ = false;                      // the master says this node is behind
  std::uint64_t skipped_ = 0;                  // frames skipped since it did
  std::uint64_t last_content_frame_ = 0;
  std::uint64_t next_frame_ = 0;
  std::uint64_t last_rendered_ = 0;
  bool rendered_any_ = false;
  std::uint64_t last_hash_ = 0;
  clock::OffsetEstimator estimator_;
  clock::Nanos frame_period_ = 0;
  int images_ = 1;  // per frame, from the job
  std::chrono::milliseconds heartbeat_{250};
  std::chrono::milliseconds liveness_timeout_{3000};
  int pings_in_burst_ = 0;
  bool ping_owed_ = false;                  // due during a round: goes when it ends
  std::optional<clock::Nanos> last_begin_;  // when the last FrameBegin came
  bool round_open_ = false;                 // a FrameBegin came; its frame is not yet shown or given up
  // A frame waiting for its present deadline, and the messages that came
  // meanwhile and must not touch the frame before it is shown.
  struct Pending {
    std::uint64_t frame_id = 0;
    clock::Nanos deadline = 0;         // monotonic, clamped
    clock::Nanos master_deadline = 0;  // as the master gave it
    bool due = false;                  // present_due() came; presented() is next
    int image = 0;                     // which of the frame's images is next
  };
  std::optional<Pending> pending_;
  std::deque<wire::Envelope> held_;

  std::chrono::milliseconds backoff_{kFirstBackoff};
  std::optional<clock::Nanos> unreachable_since_;
  int attempts_ = 0;
};

}  // namespace optique::node
