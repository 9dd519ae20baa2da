#pragma once
// What the master's core (master/protocol.h) asks its shell (master/app/master.h) to
// do, in order: send, close, set a connection's deadline, arm a timer, stop
// accepting, signal the local nodes, record the head shown and the frames
// finalized, finish, log. Apart
// from the core, so that the units it dispatches to (master/scene_server.h)
// answer in the same actions.

#include <spdlog/common.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "clock/clock.h"
#include "master/frame_rows.h"
#include "master/run/exit_codes.h"
#include "master/viewer_head.h"
#include "net/session_seal.h"
#include "optique/wire.pb.h"

namespace optique::master {

using PeerId = std::uint64_t;

// The master's timers, listed once: arming one replaces its pending time. A
// timer added to the enum is added to kTimers too (the shell has one
// steady_timer per entry, indexed by the enum's value).
enum class Timer { startup, next_frame, barrier, last_presents, goodbye, heartbeat };
inline constexpr std::array kTimers{Timer::startup,       Timer::next_frame, Timer::barrier,
                                    Timer::last_presents, Timer::goodbye,    Timer::heartbeat};
// Each entry at its enum value: no timer twice, none out of order.
[[nodiscard]] constexpr bool timers_in_order() {
  for (std::size_t i = 0; i < kTimers.size(); ++i) {
    if (static_cast<std::size_t>(kTimers[i]) != i) return false;
  }
  return true;
}
static_assert(timers_in_order(), "kTimers lists every Timer once, in the enum's order");

// --- actions

// One message to one peer. `shared`: a message sent alike to several peers (a
// frame's FrameBegin to every node), held once instead of copied for each
// (copying 1,000 instances' change eight times was a third of the master's
// time); `message` is then empty.
struct Send {
  PeerId peer = 0;
  wire::Envelope message;
  std::shared_ptr<const wire::Envelope> shared = nullptr;
  [[nodiscard]] const wire::Envelope& envelope() const { return shared ? *shared : message; }
};
struct Close {
  PeerId peer = 0;
  std::string reason;
  bool after_sending = false;  // let what is queued (a refusal, a goodbye) go first
};
// A one-shot deadline on a connection: it closes with `reason` unless cancelled.
struct SetDeadline {
  PeerId peer = 0;
  std::chrono::milliseconds after{0};
  std::string reason;
};
struct CancelDeadline {
  PeerId peer = 0;
};
struct SetLiveness {
  PeerId peer = 0;
  std::chrono::milliseconds timeout{0};
  std::string reason;
};
struct SetMaxPayload {
  PeerId peer = 0;
  std::uint32_t bytes = 0;
};
// The node proved it holds the secret: from now on everything to it is sealed
// with keys.to_node, and everything from it must open with keys.to_master.
struct Protect {
  PeerId peer = 0;
  net::SessionKeys keys;
};
struct Arm {
  Timer timer = Timer::startup;
  clock::Nanos at = 0;  // monotonic
};
struct Disarm {
  Timer timer = Timer::startup;
};
struct StopAccepting {};
struct SignalLocalNodes {
  int signal = 0;
};
// HeadShown (master/viewer_head.h): the head shown in a frame, for head.csv.
// FrameRows (master/frame_rows.h): frames finalized, for frames.csv.
// The run is over: write the outputs (report()) and end with this status.
struct Finish {
  int exit_code = kExitOk;
};
struct Log {
  spdlog::level::level_enum level = spdlog::level::info;
  std::string text;
};
// Something applications may subscribe to (a frame begun, the head shown, the
// run paused, a node down): for the scene session's subscribers. Raised only
// when there is a live scene (RunSettings::live).
struct AppEvent {
  session::Event event;
};

// An asset an application loaded is ready on every node in the frames: from
// frame `frame` on, instances of it may be created (the live scene takes it,
// the journal records it: read from `path`, identity `sha256`).
struct AssetUsable {
  std::string asset;
  std::uint64_t frame = 0;
  std::string path;
  std::string sha256;
  bool animated = false;  // it has animations: each instance plays them on its own clock
};
// An asset could not be readied on a node: it is not offered any longer.
struct AssetFailed {
  std::string asset;
  std::string reason;
};

using Action = std::variant<Send, Close, SetDeadline, CancelDeadline, SetLiveness, SetMaxPayload, Protect, Arm, Disarm,
                            StopAccepting, SignalLocalNodes, HeadShown, FrameRows, Finish, Log, AppEvent, AssetUsable,
                            AssetFailed>;
using Actions = std::vector<Action>;

}  // namespace optique::master
