#pragma once
// A render node's shell: the connection to the master (connecting, retrying),
// its timers and the renderer, around the IO-free NodeProtocol (node/protocol.h),
// which decides everything. Each socket event, timer or signal becomes one call
// of the protocol; its actions are carried out here, in order.

#include <spdlog/logger.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/thread_pool.hpp>

#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <variant>

#include "net/connection.h"
#include "node/protocol.h"
#include "node/renderer.h"
#include "node/scene_cache.h"

namespace optique::node {

namespace asio = boost::asio;

struct NodeOptions {
  std::string master_host = "127.0.0.1";
  std::string master_port;
  NodeSettings protocol;  // what the protocol needs (id, secret, test hooks)
  // Wake up this long before a present deadline, then spin: covers the
  // scheduler's wake-up delay when every node of a machine wakes at once.
  std::chrono::microseconds present_spin{200};
  // Where copies of the master's glTF scenes are kept: in its scenes/
  // (node/scene_cache.h).
  std::string cache_dir = SceneCache::default_cache_dir().string();
};

class Node {
 public:
  Node(asio::io_context& io, NodeOptions options, Renderer& renderer, spdlog::logger& log);
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  void start();
  [[nodiscard]] int exit_code() const { return exit_code_; }

 private:
  void connect();
  void carry_out(Actions actions);
  void carry_out(Action& action);
  // Queues the answer to an action (or a timer already run out while carrying
  // one out), for carry_out to give the core after the list.
  void complete(std::variant<Answer, Due> event, clock::Nanos at);
  void wait_for_present(clock::Nanos deadline);
  void on_signal(int signal);

  asio::io_context& io_;
  NodeOptions options_;
  NodeProtocol protocol_;
  Renderer& renderer_;
  spdlog::logger& log_;

  asio::ip::tcp::resolver resolver_;
  asio::steady_timer retry_timer_;
  asio::steady_timer ping_timer_;
  asio::steady_timer scene_timer_;  // looking again at another node's copy of the scene
  asio::steady_timer connect_timer_;
  asio::steady_timer present_timer_;
  std::shared_ptr<asio::ip::tcp::socket> connecting_;
  asio::signal_set signals_;
  SceneCache scene_cache_;
  std::shared_ptr<net::Connection> connection_;
  int exit_code_ = kExitOk;
  struct Completion {
    std::variant<Answer, Due> event;
    clock::Nanos at = 0;
  };
  std::deque<Completion> completions_;
  int depth_ = 0;  // carry_out calls running (a Close calls back into it)
  // What the loader's thread posts back finds the node gone once it is.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
  // Reads assets offered while frames go on (Renderer::read_asset), one at a
  // time; joined first when the node goes.
  asio::thread_pool loader_{1};
};

}  // namespace optique::node
