#include "node/node.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/post.hpp>

#include <csignal>
#include <cstring>
#include <thread>

#include "net/auth.h"
#include "util/background_thread.h"
#include "util/overloaded.h"

namespace optique::node {

namespace {
// A master host that drops connection attempts silently would keep a connect
// pending for minutes of kernel retries: bound it.
constexpr std::chrono::milliseconds kConnectTimeout{3000};

}  // namespace

Node::Node(asio::io_context& io, NodeOptions options, Renderer& renderer, spdlog::logger& log)
    : io_(io),
      options_(std::move(options)),
      protocol_(options_.protocol),
      renderer_(renderer),
      log_(log),
      resolver_(io),
      retry_timer_(io),
      ping_timer_(io),
      scene_timer_(io),
      connect_timer_(io),
      present_timer_(io),
      signals_(io, SIGINT, SIGTERM),
      scene_cache_(options_.cache_dir, log) {
  asio::post(loader_, [&log] {
    if (const std::string why = util::lower_this_threads_priority(); !why.empty()) {
      log.debug("the asset loader's thread keeps its priority: {}", why);
    }
  });
}

void Node::start() {
  signals_.async_wait([this](const boost::system::error_code& error, int signal) {
    if (!error) on_signal(signal);
  });
  connect();
}

void Node::on_signal(int signal) { carry_out(protocol_.interrupted(strsignal(signal))); }

void Node::connect() {
  if (protocol_.stopped()) return;
  resolver_.async_resolve(
      options_.master_host, options_.master_port,
      [this](const boost::system::error_code& error, const asio::ip::tcp::resolver::results_type& endpoints) {
        if (protocol_.stopped()) return;
        if (error) {
          carry_out(protocol_.connect_failed("cannot resolve " + options_.master_host + ": " + error.message(),
                                             clock::monotonic_now()));
          return;
        }
        auto socket = std::make_shared<asio::ip::tcp::socket>(io_);
        connecting_ = socket;
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
              if (protocol_.stopped()) return;
              if (e) {
                carry_out(protocol_.connect_failed(
                    e == asio::error::operation_aborted ? "no answer to the connection attempt" : e.message(),
                    clock::monotonic_now()));
                return;
              }
              connection_ = net::Connection::create(std::move(*socket), net::kDefaultMaxPayloadBytes);
              connection_->start({
                  [this](wire::Envelope& message, clock::Nanos received) {
                    carry_out(protocol_.message(message, received));
                  },
                  [this](const std::string& reason) { carry_out(protocol_.closed(reason, clock::monotonic_now())); },
                  {},  // a master's message over the size closes it
              });
              log_.debug("connected to the master at {}", connection_->peer());
              carry_out(protocol_.connected(clock::monotonic_now(), net::random_nonce()));
            });
      });
}

// The answers an action asks for (configured, rendered, presented, the cache's)
// are queued and given to the core after the whole list, in the order they
// came, by the outermost call: the core never hears of an action's outcome
// while the rest of its list is still being carried out. (A Close reaches the
// core at once, as closed(): the connection calls back when it closes.)
void Node::carry_out(Actions actions) {
  // Once the core stopped (the master gone for good), what came after in this
  // list is moot (a deadline, a step of a fetch that has ended); the stop's own
  // list (goodbye, close, stop) began stopped and runs whole.
  const auto run = [this](Actions& list) {
    const bool stopped_before = protocol_.stopped();
    for (Action& action : list) {
      if (!stopped_before && protocol_.stopped()) break;
      carry_out(action);
    }
  };
  ++depth_;
  run(actions);
  if (depth_ == 1) {
    while (!completions_.empty() && !protocol_.stopped()) {
      Completion next = std::move(completions_.front());
      completions_.pop_front();
      Actions more = std::visit(util::Overloaded{
                                    [&](Answer& answer) { return protocol_.answer(std::move(answer), next.at); },
                                    [&](Due timer) { return protocol_.due(timer, next.at); },
                                },
                                next.event);
      run(more);
    }
    completions_.clear();  // after a stop: moot
  }
  --depth_;
}

void Node::complete(std::variant<Answer, Due> event, clock::Nanos at) {
  completions_.push_back(Completion{std::move(event), at});
}

void Node::carry_out(Action& action) {
  std::visit(util::Overloaded{
                 [&](Send& a) {
                   if (!connection_ || !connection_->is_open()) return;
                   // A ping's t1 is when it leaves, as the master's pong t3 is: the
                   // legs are measured alike.
                   if (a.message.has_ping()) a.message.mutable_ping()->set_t1(options_.protocol.clock.now());
                   connection_->send(a.message);
                 },
                 [&](Close& a) {
                   if (!connection_ || !connection_->is_open()) return;
                   if (a.after_sending) {
                     connection_->close_after_sending(a.reason);
                   } else {
                     connection_->close(a.reason);
                   }
                 },
                 [&](SetDeadline& a) {
                   if (connection_) connection_->set_deadline(a.after, a.reason);
                 },
                 [&](CancelDeadline&) {
                   if (connection_) connection_->cancel_deadline();
                 },
                 [&](Protect& a) {
                   if (connection_) connection_->protect(a.send, a.receive, true);
                 },
                 [&](SetLiveness& a) {
                   if (connection_) connection_->set_liveness_timeout(a.timeout, a.reason);
                 },
                 [&](Configure& a) {
                   Result<void> result = renderer_.configure(a.job);
                   complete(Configured{std::move(result), renderer_.description(), renderer_.warm_up()},
                            clock::monotonic_now());
                 },
                 [&](Render& a) {
                   const clock::Nanos started = clock::monotonic_now();
                   const Rendered how = renderer_.render(a.frame);
                   const clock::Nanos done = clock::monotonic_now();
                   complete(FrameRendered{a.frame.frame_id, done - started, how}, done);
                 },
                 [&](Skip& a) { renderer_.skip(a.frame); },
                 [&](PresentAt& a) { wait_for_present(a.deadline); },
                 [&](Present& a) {
                   renderer_.present(a.image);
                   const clock::Nanos shown = clock::monotonic_now();
                   // Nodes sharing a machine present at the same instant: let the others
                   // on this core show theirs before this one does its bookkeeping.
                   std::this_thread::yield();
                   complete(ImagePresented{}, shown);
                 },
                 [&](ShowBlack&) { renderer_.show_black(); },
                 [&](PingIn& a) {
                   ping_timer_.expires_after(a.after);
                   ping_timer_.async_wait([this](const boost::system::error_code& error) {
                     if (!error) carry_out(protocol_.due(Due::ping, clock::monotonic_now()));
                   });
                 },
                 [&](CancelPings&) { ping_timer_.cancel(); },
                 [&](Reconnect& a) {
                   retry_timer_.expires_after(a.after);
                   retry_timer_.async_wait([this](const boost::system::error_code& error) {
                     if (!error) connect();
                   });
                 },
                 [&](Stop& a) {
                   exit_code_ = a.exit_code;
                   retry_timer_.cancel();
                   ping_timer_.cancel();
                   scene_timer_.cancel();
                   connect_timer_.cancel();
                   present_timer_.cancel();
                   signals_.cancel();
                   resolver_.cancel();
                   if (connecting_) {
                     boost::system::error_code ignored;
                     connecting_->close(ignored);
                   }
                 },
                 [&](Log& a) { log_.log(a.level, "{}", a.text); },
                 [&](PrepareScene& a) {
                   if (auto found = scene_cache_.find(a.manifest, a.sha256)) {
                     complete(SceneFound{*found}, clock::monotonic_now());
                     return;
                   }
                   Result<SceneCache::Begun> begun = scene_cache_.begin(a.manifest, a.sha256, a.wait_for_others);
                   if (!begun) {
                     complete(SceneCopyStarted{Error{begun.error()}}, clock::monotonic_now());
                   } else if (const auto* elsewhere = std::get_if<SceneCache::FetchedElsewhere>(&begun.value())) {
                     complete(SceneFetchedElsewhere{elsewhere->bytes_there}, clock::monotonic_now());
                   } else {
                     complete(SceneCopyStarted{std::get<SceneCache::Present>(std::move(begun).value())},
                              clock::monotonic_now());
                   }
                 },
                 [&](RecheckScene& a) {
                   scene_timer_.expires_after(a.after);
                   scene_timer_.async_wait([this](const boost::system::error_code& error) {
                     if (!error) carry_out(protocol_.due(Due::scene_recheck, clock::monotonic_now()));
                   });
                 },
                 [&](StoreSceneChunk& a) {
                   if (auto stored = scene_cache_.write(a.file, a.offset, a.data); !stored) {
                     complete(SceneStoreFailed{stored.error()}, clock::monotonic_now());
                   }
                 },
                 [&](FinishScene&) { complete(SceneCopyFinished{scene_cache_.commit()}, clock::monotonic_now()); },
                 [&](AbandonScene&) { scene_cache_.abandon(); },
                 // Read off this thread (the frames go on meanwhile), given to the GPU on it.
                 [&](ReadyAsset& a) {
                   const std::weak_ptr<bool> alive = alive_;
                   asio::post(loader_, [this, alive, offer = std::move(a.asset)]() mutable {
                     auto read = renderer_.read_asset(offer);
                     asio::post(io_, [this, alive, offer = std::move(offer), read = std::move(read)] {
                       if (alive.expired() || protocol_.stopped()) return;
                       Result<void> added =
                           read ? renderer_.add_asset(offer, *read.value()) : Result<void>{Error{read.error()}};
                       carry_out(protocol_.answer(AssetLoaded{offer.asset, std::move(added)}, clock::monotonic_now()));
                     });
                   });
                 },
             },
             action);
}

// The wait for a present deadline holds up nothing: pongs keep being stamped as
// they come (the clock estimate depends on it), and a frame that arrives
// meanwhile waits in the protocol. The last `present_spin` is spun, since a
// timer wakes up late by the scheduler's delay.
void Node::wait_for_present(clock::Nanos deadline) {
  const clock::Nanos spin = options_.present_spin.count() * clock::kNanosPerMicro;
  const clock::Nanos wake = deadline - spin - clock::monotonic_now();
  if (wake <= 0) {
    clock::sleep_until_monotonic(deadline, spin);
    complete(Due::present, clock::monotonic_now());  // given after this list
    return;
  }
  present_timer_.expires_after(std::chrono::nanoseconds(wake));
  present_timer_.async_wait([this, deadline, spin](const boost::system::error_code& error) {
    if (error) return;
    clock::sleep_until_monotonic(deadline, spin);
    carry_out(protocol_.due(Due::present, clock::monotonic_now()));
  });
}

}  // namespace optique::node
