#pragma once
// A render node: connects to the master (retrying with backoff while it is not
// up), handshakes, applies the snapshot and per-frame deltas, renders, reports
// ready, and presents at the master's deadline converted to its own clock.

#include <spdlog/logger.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>

#include "clock/clock.h"
#include "clock/offset_estimator.h"
#include "net/auth.h"
#include "net/connection.h"
#include "net/envelope.h"
#include "node/renderer.h"
#include "scene/state.h"

namespace optique::node {

namespace asio = boost::asio;

struct NodeOptions {
  std::string master_host = "127.0.0.1";
  std::string master_port;
  std::string id;
  std::chrono::milliseconds give_up_after{10000};          // master unreachable this long: exit
  std::uint32_t protocol_version = net::kProtocolVersion;  // test hook: speak another version
  std::optional<net::Secret> secret;                       // proves to the master this node belongs
  clock::LocalClock clock;                                 // test hook: a skewed clock
  // Test hook: show the content of this many frames ago, as a node out of step
  // with its stacked partners would (reported in Presented.content_frame_id).
  std::uint32_t lag_frames = 0;
  // Test hook: nudge the scene state at this frame, as a bit flip or a bug would,
  // to see the master notice and repair it (0: never).
  std::uint64_t corrupt_state_at_frame = 0;
  // Sleep until this long before a present deadline, then spin: covers the
  // scheduler's wake-up delay when every node of a machine wakes at once.
  std::chrono::microseconds present_spin{200};
  // When the master is lost: show black (a frozen wall looks like a fault in the
  // show), or keep the last frame.
  bool hold_last_frame = false;
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitRefused = 2;   // refused by the master, or bad command line
inline constexpr int kExitNoMaster = 3;  // gave up reaching the master

class Node {
 public:
  Node(asio::io_context& io, NodeOptions options, Renderer& renderer, spdlog::logger& log);
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  void start();
  [[nodiscard]] int exit_code() const { return exit_code_; }

 private:
  enum class Phase { disconnected, awaiting_challenge, awaiting_welcome, awaiting_state, joined, stopped };

  void connect();
  void on_connected(asio::ip::tcp::socket socket);
  void retry_later(const std::string& reason);
  void on_message(wire::Envelope& message);
  void on_closed(const std::string& reason);
  void handle_challenge(wire::Envelope& message);
  void handle_welcome(const wire::Welcome& welcome);
  void handle_resync(const wire::Resync& resync);
  void handle_frame_begin(const wire::FrameBegin& begin);
  void handle_swap(const wire::FrameSwap& swap);
  void handle_pong(const wire::Pong& pong);
  void send_ping();
  void schedule_pings(std::chrono::milliseconds interval);
  void on_signal(int signal);
  void stop(int exit_code, const std::string& reason);

  asio::io_context& io_;
  NodeOptions options_;
  Renderer& renderer_;
  spdlog::logger& log_;

  asio::ip::tcp::resolver resolver_;
  asio::steady_timer retry_timer_;
  asio::steady_timer ping_timer_;
  asio::steady_timer connect_timer_;
  std::shared_ptr<asio::ip::tcp::socket> connecting_;
  asio::signal_set signals_;
  std::shared_ptr<net::Connection> connection_;

  Phase phase_ = Phase::disconnected;
  scene::SceneState state_;
  // The lag hook's memory: the last lag_frames + 1 frames as they came.
  struct PastFrame {
    wire::FrameBegin begin;
    scene::SceneState state;
  };
  std::deque<PastFrame> past_frames_;
  std::uint64_t last_content_frame_ = 0;
  clock::OffsetEstimator estimator_;
  std::uint64_t next_frame_ = 0;
  std::uint64_t last_rendered_ = 0;
  bool rendered_any_ = false;
  clock::Nanos frame_period_ = 0;
  std::uint32_t light_count_ = 0;  // the scene's, from the welcome: shares name fewer
  std::chrono::milliseconds heartbeat_{250};
  std::chrono::milliseconds liveness_timeout_{3000};
  int pings_in_burst_ = 0;

  std::chrono::milliseconds backoff_{100};
  std::chrono::steady_clock::time_point unreachable_since_;
  bool unreachable_ = false;
  int attempts_ = 0;
  int exit_code_ = kExitOk;
};

}  // namespace optique::node
