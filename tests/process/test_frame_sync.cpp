// Frame sync through failures, with real master and node processes on 127.0.0.1:
// repairs, stragglers, a master or a node killed and restarted, connection
// resets, and the shared secret. (What depends on timing precision — clock
// estimates, present skew — is in tests/timing.)

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <fstream>
#include <functional>
#include <thread>

#include "cluster_run.h"
#include "config/load.h"
#include "external_master.h"
#include "fault_proxy.h"
#include "net/auth.h"
#include "net/envelope.h"
#include "net/framing.h"
#include "process.h"
#include "screen_check.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

// How many times the master's log says node `id` joined.
std::size_t times_joined(const Process& master, const std::string& id) {
  const std::string log = master.output();
  const std::string line = "node '" + id + "' joined";
  std::size_t count = 0;
  for (auto at = log.find(line); at != std::string::npos; at = log.find(line, at + 1)) ++count;
  return count;
}

// A node whose state goes wrong (the test hook nudges it at frame 30) is found
// out at that frame and repaired with a snapshot: its hash matches again from the
// next frame on, and it presents every frame.
TEST(FrameSync, AStateHashMismatchIsRepairedWithinOneFrame) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  ExternalMaster master(config, {"--frames", "90"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  const NullNodes started = start_null_nodes(master, config, [](std::size_t i) {
    return i == 0 ? std::vector<std::string>{"--corrupt-state-at-frame", "30"} : std::vector<std::string>{};
  });
  const std::vector<std::string>& ids = started.ids;
  const auto& nodes = started.processes;
  ASSERT_EQ(master.process->wait(60s).value_or(-1), 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const report::NodeReport* corrupted = find_node(run.report, ids.front());
  EXPECT_EQ(corrupted->hash_mismatches(), 1u) << "found at frame 30, matching again from frame 31";
  EXPECT_EQ(corrupted->frames_presented(), 90u);
  EXPECT_EQ(run.report.sync().frames_incoherent(), 0u);
  EXPECT_NE(master.process->output().find("for frame 30, master has"), std::string::npos) << master.process->output();
  EXPECT_TRUE(nodes.front()->wait(10s).has_value());
  EXPECT_NE(nodes.front()->output().find("state resynchronized at frame 31"), std::string::npos)
      << nodes.front()->output();
}

// Straggler policy "drop", frame timeout 500 ms, four null nodes at 30 Hz. One
// node stopped for half the timeout is waited for (no frame lost); stopped for
// twice the timeout, the frame it holds up is shown by nobody, it leaves the
// barrier, and after SIGCONT it answers again and shows frames once more.
TEST(FrameSync, AStragglerIsWaitedForThenItsFrameIsDroppedEverywhere) {
  const ScratchDir dir_scratch("optique-straggler");
  const std::string dir = dir_scratch.string();
  const std::string config = write_config_variant(
      kConfigs + "/powerwall-2x2.json",
      [](schema::Installation& installation) {
        installation.mutable_master()->set_straggler_policy("drop");
        installation.mutable_master()->set_frame_rate(30.0);
      },
      dir + "/drop.json");
  ExternalMaster master(config, {"--frames", "240"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  const NullNodes started = start_null_nodes(master, config);
  const std::vector<std::string>& ids = started.ids;
  const auto& nodes = started.processes;
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 20s)) << master.process->output();
  std::this_thread::sleep_for(1s);
  nodes.back()->signal(SIGSTOP);
  std::this_thread::sleep_for(250ms);  // half the timeout
  nodes.back()->signal(SIGCONT);
  std::this_thread::sleep_for(1s);
  EXPECT_EQ(master.process->output().find("was not ready"), std::string::npos) << "waited for, not dropped";
  nodes.back()->signal(SIGSTOP);
  ASSERT_TRUE(master.process->wait_for_output("was not ready", 5s)) << master.process->output();
  std::this_thread::sleep_for(1s);  // twice the timeout
  nodes.back()->signal(SIGCONT);
  ASSERT_EQ(master.process->wait(60s).value_or(-1), 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const auto& sync = run.report.sync();
  EXPECT_EQ(sync.frames_dropped(), 1u);
  EXPECT_EQ(find_node(run.report, ids.back())->barrier_misses(), 1u);
  for (std::size_t i = 0; i + 1 < ids.size(); ++i) {
    EXPECT_EQ(find_node(run.report, ids[i])->frames_presented(), 239u) << ids[i] << ": all but the dropped frame";
  }
  const auto* straggler = find_node(run.report, ids.back());
  EXPECT_GT(straggler->frames_presented(), 150u) << "it came back";
  EXPECT_LT(straggler->frames_presented(), 239u);
  EXPECT_NE(master.process->output().find("answers again"), std::string::npos) << master.process->output();
  // A stop that lands between a swap and its present holds that frame past its
  // time: the node then does not show it (never a stale frame), which counts as
  // incoherent; at most once per stop.
  EXPECT_LE(sync.frames_incoherent(), 2u);
  // No frame shown late. The node's stale-frame guard drops a frame one period
  // (33 ms here) past its deadline (its edge: the unit test
  // AFrameIsStaleOneFramePeriodAfterItsDeadline); this bound is below it, so a
  // guard that fired late would fail here. Above it: what this VM does to a
  // present on time (a core held back for up to 16 ms now and then; 5 ms failed
  // once in about six runs).
  EXPECT_LT(sync.present_skew_us().max(), 25'000.0 * timing_scale()) << "no frame shown late";
}

// The master killed mid-run: its nodes show black and reconnect with backoff; a
// master restarted on the same port takes them back and they show its frames.
TEST(FrameSync, NodesShowBlackWhileTheMasterIsGoneAndARestartedMasterTakesThemBack) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  const std::string port = free_port();
  const ScratchDir dir_scratch("optique-restart");
  const std::string dir = dir_scratch.string();
  const auto start_master = [&](const std::string& name, const std::string& frames) {
    return std::make_unique<Process>(
        std::vector<std::string>{master_binary(), "--config", config, "--listen", "127.0.0.1", "--port", port,
                                 "--frames", frames, "--out", dir + "/" + name, "--no-status"},
        dir + "/" + name + ".log");
  };
  auto first = start_master("first", "0");
  std::vector<std::unique_ptr<Process>> nodes;
  auto loaded = config::load_installation(config);
  ASSERT_TRUE(loaded) << loaded.error();
  for (const auto& p : loaded.value().installation.projectors) {
    nodes.push_back(
        std::make_unique<Process>(std::vector<std::string>{node_binary(), "--master", "127.0.0.1:" + port, "--id", p.id,
                                                           "--renderer", "null", "--give-up-after-ms", "20000"},
                                  dir + "/node-" + p.id + ".log"));
  }
  ASSERT_TRUE(first->wait_for_output("starting frames", 20s)) << first->output();
  std::this_thread::sleep_for(1s);
  first->signal(SIGKILL);
  ASSERT_EQ(first->wait(10s).value_or(-1), 128 + SIGKILL);
  for (const auto& node : nodes) {
    EXPECT_TRUE(node->wait_for_output("showing black while reconnecting", 10s)) << node->output();
  }
  std::this_thread::sleep_for(1s);
  for (const auto& node : nodes) EXPECT_TRUE(node->running()) << "still trying: " << node->output();
  auto second = start_master("second", "120");
  ASSERT_EQ(second->wait(60s).value_or(-1), 0) << second->output();
  const ClusterRun run = read_cluster_run(dir + "/second");
  ASSERT_TRUE(run.error.empty()) << run.error;
  for (const auto& p : loaded.value().installation.projectors) {
    EXPECT_EQ(find_node(run.report, p.id)->frames_presented(), 120u) << p.id;
  }
  EXPECT_EQ(run.report.sync().frames_incoherent(), 0u);
  for (const auto& node : nodes) EXPECT_EQ(node->wait(10s).value_or(-1), 0) << node->output();
}

// A node SIGKILLed mid-run and started again: the others never wait for it; it
// rejoins at a frame boundary with a fresh snapshot, its state hash matches the
// master's from its first frame back, and from there it shows every frame once,
// in order, to the end.
TEST(FrameSync, AKilledNodeRestartedRejoinsAndShowsEveryFrameFromThere) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  constexpr std::uint64_t kFrames = 360;  // 6 s at 60 Hz
  ExternalMaster master(config, {"--frames", std::to_string(kFrames), "--log-level", "info"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  NullNodes started = start_null_nodes(master, config);
  const std::vector<std::string>& ids = started.ids;
  ASSERT_EQ(ids.size(), 4u);
  const std::string victim = ids.back();
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 20s)) << master.process->output();
  std::this_thread::sleep_for(1s);
  started.processes.back()->signal(SIGKILL);
  ASSERT_EQ(started.processes.back()->wait(10s).value_or(-1), 128 + SIGKILL);
  ASSERT_TRUE(master.process->wait_for_output("node '" + victim + "' left", 5s)) << master.process->output();
  started.processes.back() = master.node(victim, {"--renderer", "null"});
  ASSERT_TRUE(poll_until([&] { return times_joined(*master.process, victim) == 2; }, 10s)) << master.process->output();
  ASSERT_EQ(master.process->wait(60s).value_or(-1), 0) << master.process->output();
  for (const auto& node : started.processes) EXPECT_EQ(node->wait(10s).value_or(-1), 0) << node->output();

  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const std::vector<std::string> survivors(ids.begin(), ids.end() - 1);
  for (const auto& id : survivors) EXPECT_EQ(find_node(run.report, id)->frames_presented(), kFrames) << id;
  const std::vector<std::string> problems = sync_problems(run, survivors, kFrames);
  EXPECT_TRUE(problems.empty()) << problems.front();
  const report::NodeReport* restarted = find_node(run.report, victim);
  ASSERT_NE(restarted, nullptr);
  EXPECT_EQ(restarted->joins(), 2u);
  EXPECT_EQ(restarted->hash_mismatches(), 0u) << "its hash matched from its first frame back";

  // The frames it showed: a run before the kill, a gap, then every frame to the end.
  std::vector<std::uint64_t> shown;
  for (const auto& row : run.rows) {
    if (row.node == victim && row.presented != 0) shown.push_back(row.frame);
  }
  std::sort(shown.begin(), shown.end());
  EXPECT_EQ(std::adjacent_find(shown.begin(), shown.end()), shown.end()) << "no frame shown twice";
  std::vector<std::pair<std::uint64_t, std::uint64_t>> runs;  // [first, last] of each contiguous stretch
  for (const std::uint64_t frame : shown) {
    if (runs.empty() || frame != runs.back().second + 1) {
      runs.emplace_back(frame, frame);
    } else {
      runs.back().second = frame;
    }
  }
  ASSERT_EQ(runs.size(), 2u) << "shown before the kill, then from the rejoin on";
  EXPECT_EQ(runs.front().first, 0u);
  EXPECT_EQ(runs.back().second, kFrames - 1);
  EXPECT_GT(runs.back().first, runs.front().second + 1);
  const std::string node_log = started.processes.back()->output();
  EXPECT_EQ(node_log.find("frame ids jumped"), std::string::npos) << node_log;
  EXPECT_EQ(node_log.find("differs from the master's"), std::string::npos) << node_log;
  std::cout << "killed after frame " << runs.front().second << ", back from frame " << runs.back().first << " of "
            << kFrames << "\n";
}

// One node reaches the master through the fault proxy, which resets its
// connection 100 times: it rejoins every time with a fresh snapshot, its state
// hash always matches, and its frame ids never repeat or skip.
TEST(FrameSync, AHundredConnectionResetsAllResync) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  ExternalMaster master(config, {"--frames", "0", "--log-level", "info"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  FaultProxy proxy(static_cast<std::uint16_t>(std::stoi(master.port)));
  auto loaded = config::load_installation(config);
  ASSERT_TRUE(loaded) << loaded.error();
  std::vector<std::unique_ptr<Process>> nodes;
  std::vector<std::string> ids;
  for (const auto& p : loaded.value().installation.projectors) ids.push_back(p.id);
  const std::string through_proxy = ids.front();
  for (const auto& id : ids) {
    if (id == through_proxy) {
      nodes.push_back(std::make_unique<Process>(
          std::vector<std::string>{node_binary(), "--master", "127.0.0.1:" + std::to_string(proxy.port()), "--id", id,
                                   "--renderer", "null", "--give-up-after-ms", "20000"},
          master.dir + "/node-" + id + ".log"));
    } else {
      nodes.push_back(master.node(id, {"--renderer", "null"}));
    }
  }
  ASSERT_TRUE(master.process->wait_for_output("starting frames", 20s)) << master.process->output();
  const auto joins = [&] { return times_joined(*master.process, through_proxy); };
  for (int reset = 1; reset <= 100; ++reset) {
    ASSERT_TRUE(poll_until([&] { return joins() == static_cast<std::size_t>(reset); }, 10s))
        << "rejoin " << reset << ":\n"
        << master.process->output();
    std::this_thread::sleep_for(std::chrono::milliseconds(20 + (reset * 37) % 80));  // a few frames in
    EXPECT_EQ(proxy.reset_all(), 1u);
  }
  ASSERT_TRUE(poll_until([&] { return joins() == 101; }, 10s)) << master.process->output();
  std::this_thread::sleep_for(500ms);
  master.process->signal(SIGINT);
  ASSERT_EQ(master.process->wait(30s).value_or(-1), 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  const report::NodeReport* node = find_node(run.report, through_proxy);
  EXPECT_EQ(node->joins(), 101u);
  for (const auto& id : ids) EXPECT_EQ(find_node(run.report, id)->hash_mismatches(), 0u) << id;
  EXPECT_GT(node->frames_presented(), 100u);
  EXPECT_TRUE(nodes.front()->wait(10s).has_value());
  const std::string node_log = nodes.front()->output();
  EXPECT_EQ(node_log.find("frame ids jumped"), std::string::npos) << node_log;
  EXPECT_EQ(node_log.find("differs from the master's"), std::string::npos) << node_log;
  std::cout << "100 resets: " << node->joins() << " joins, " << node->frames_presented() << " frames presented of "
            << run.report.frames() << ", 0 hash mismatches\n";
}

// ------------------------------------------------------------- intruders

// A TCP client that speaks just enough of the protocol to misbehave.
class RawClient {
 public:
  RawClient(const std::string& host, const std::string& port) {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    timeval timeout{5, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<std::uint16_t>(std::stoi(port)));
    inet_pton(AF_INET, host.c_str(), &address.sin_addr);
    connected_ = connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
  }
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;
  ~RawClient() { close(fd_); }

  [[nodiscard]] bool connected() const { return connected_; }
  void send_bytes(const std::vector<std::uint8_t>& bytes) const {
    [[maybe_unused]] const auto sent = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  }
  void send(wire::Envelope envelope) {
    envelope.set_sequence(++sequence_);  // the master checks that every peer counts its messages
    std::vector<std::uint8_t> bytes;
    net::append_envelope(bytes, envelope);
    send_bytes(bytes);
  }
  // The next message, or nothing when the master closed the connection or 5 s passed.
  [[nodiscard]] std::optional<wire::Envelope> receive() {
    std::uint8_t buffer[4096];
    for (;;) {
      const auto frame = reader_.next();
      if (frame.status == net::DecodeStatus::good) {
        auto envelope = net::parse_envelope(frame.payload);
        if (envelope) return envelope.value();
        return std::nullopt;
      }
      if (frame.status == net::DecodeStatus::bad) return std::nullopt;
      const auto got = recv(fd_, buffer, sizeof buffer, 0);
      if (got <= 0) return std::nullopt;
      reader_.append(std::span(buffer, static_cast<std::size_t>(got)));
    }
  }
  // Whether the master closed the connection within `timeout`.
  [[nodiscard]] bool closed_within(std::chrono::milliseconds timeout) const {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::uint8_t buffer[4096];
    do {
      const auto got = recv(fd_, buffer, sizeof buffer, MSG_DONTWAIT);  // the challenge may come first
      if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK)) return true;
      if (got < 0) std::this_thread::sleep_for(5ms);
    } while (std::chrono::steady_clock::now() < deadline);
    return false;
  }

 private:
  int fd_ = -1;
  bool connected_ = false;
  std::uint64_t sequence_ = 0;
  net::FrameReader reader_{1u << 20};
};

std::vector<std::uint8_t> bytes_of(const std::string& text) { return {text.begin(), text.end()}; }

// The node's own nonce, the same in every hello here (a relay forwards a real
// node's hello as it is).
const std::string kNodeNonce(net::kNonceBytes, 'n');

wire::Envelope hello(const std::string& id, const std::string& mac) {
  wire::Envelope envelope;
  envelope.set_protocol_version(net::kProtocolVersion);
  envelope.mutable_hello()->set_node_id(id);
  envelope.mutable_hello()->set_nonce_mac(mac);
  envelope.mutable_hello()->set_node_nonce(kNodeNonce);
  return envelope;
}

// The mac a node holding `secret` answers the challenge `nonce` with.
std::string mac_text(const net::Secret& secret, const std::string& nonce, const std::string& id) {
  const auto mac = net::hello_mac(secret, bytes_of(nonce + kNodeNonce), id, net::kProtocolVersion);
  return {mac.begin(), mac.end()};
}

// A two-projector wall whose master requires the secret in DIR/secret (mode 0600).
struct SecretWall {
  ScratchDir dir_scratch{"optique-secret"};
  const std::string dir = dir_scratch.string();
  std::string config = dir + "/wall.json";
  std::string secret_file = dir + "/secret";
  net::Secret secret;

  explicit SecretWall(mode_t mode = 0600, const std::string& frame_rate = "60") {
    std::ofstream(secret_file) << "correct horse battery staple\n";
    chmod(secret_file.c_str(), mode);
    secret.bytes = bytes_of("correct horse battery staple");
    std::ofstream(config) << R"({"screens": [{"id": "wall", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0],
      "width": 4, "height": 2.25}],
      "projectors": [{"id": "left", "width": 160, "height": 90, "screen": "wall",
                      "region": {"x": 0, "y": 0, "width": 2, "height": 2.25}},
                     {"id": "right", "width": 160, "height": 90, "screen": "wall",
                      "region": {"x": 2, "y": 0, "width": 2, "height": 2.25}}],
      "viewer": {"eye": [0, 1.6, 2]}, "master": {"frame_rate": )"
                          << frame_rate << R"(, "secret_file": "secret"}, "scene": {"builtin": "cubes"}})";
  }
};

TEST(Security, OnlyNodesWithTheSecretJoin) {
  const SecretWall wall;
  ExternalMaster master(wall.config, {"--frames", "120"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto left = master.node("left", {"--renderer", "null", "--secret-file", wall.secret_file});
  // An impostor with another secret, then one with none: each told why, each exits 2.
  const std::string wrong = master.dir + "/wrong";
  std::ofstream(wrong) << "a different secret of some length\n";
  chmod(wrong.c_str(), 0600);
  auto impostor = master.node("right", {"--renderer", "null", "--secret-file", wrong});
  EXPECT_EQ(impostor->wait(20s).value_or(-1), 2) << impostor->output();
  EXPECT_NE(impostor->output().find("authentication failed"), std::string::npos) << impostor->output();
  auto bare = master.node("right", {"--renderer", "null"});
  EXPECT_EQ(bare->wait(20s).value_or(-1), 2) << bare->output();
  EXPECT_NE(bare->output().find("--secret-file"), std::string::npos) << bare->output();
  auto right = master.node("right", {"--renderer", "null", "--secret-file", wall.secret_file});
  ASSERT_EQ(master.process->wait(60s).value_or(-1), 0) << master.process->output();
  const ClusterRun run = read_cluster_run(master.dir + "/out");
  ASSERT_TRUE(run.error.empty()) << run.error;
  EXPECT_EQ(find_node(run.report, "left")->frames_presented(), 120u);
  EXPECT_GT(find_node(run.report, "right")->frames_presented(), 0u);
  EXPECT_EQ(run.report.connections_refused(), 2u);
  const std::string log = master.process->output();
  EXPECT_NE(log.find("refused node 'right' from 127.0.0.1:"), std::string::npos) << log;
  EXPECT_NE(log.find("authentication failed: the node's secret does not match"), std::string::npos) << log;
}

// A relay between a node and the real master passes the node's hello on (it
// needs no secret for that), then speaks for the projector itself: after the
// hello every message is sealed with keys from the secret and both nonces, so
// what the relay says fails to open, the master drops the connection, and the
// relay cannot read the welcome either.
TEST(Security, ARelayThatPassesTheHelloOnCannotSpeakForTheNode) {
  const SecretWall wall;
  ExternalMaster master(wall.config, {"--frames", "60"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  RawClient relay("127.0.0.1", master.port);
  const auto challenge = relay.receive();
  ASSERT_TRUE(challenge && challenge->has_challenge());
  relay.send(hello("left", mac_text(wall.secret, challenge->challenge().nonce(), "left")));  // the node's, passed on
  EXPECT_FALSE(relay.receive().has_value()) << "the welcome is sealed: the relay cannot read it";
  wire::Envelope forged;
  forged.set_protocol_version(net::kProtocolVersion);
  forged.mutable_configured()->set_renderer("the relay, as projector 'left'");
  relay.send(forged);
  EXPECT_TRUE(relay.closed_within(scaled(5s)));
  EXPECT_TRUE(master.process->wait_for_output("failed authentication", scaled(5s))) << master.process->output();
  EXPECT_EQ(master.process->output().find("joined"), std::string::npos) << "nobody joined as 'left'";
}

// A node with the installation's secret does not join a master that asks for
// none (anyone could run one): it says why and exits 2, and caches nothing.
TEST(Security, ANodeWithTheSecretDoesNotJoinAMasterWithout) {
  const SecretWall wall;
  ExternalMaster master(std::string(OPTIQUE_SOURCE_DIR) + "/configs/single-wall.json", {"--frames", "30"});
  ASSERT_FALSE(master.port.empty()) << master.process->output();
  auto node = master.node("wall", {"--renderer", "null", "--secret-file", wall.secret_file});
  EXPECT_EQ(node->wait(20s).value_or(-1), 2) << node->output();
  EXPECT_NE(node->output().find("asked for no secret, but this node has one"), std::string::npos) << node->output();
}

TEST(Security, AWorldReadableSecretFileStopsTheMasterBeforeAnythingStarts) {
  const SecretWall wall(0644);
  Process master({master_binary(), "--config", wall.config, "--no-status"}, wall.dir + "/master.log");
  EXPECT_EQ(master.wait(20s).value_or(-1), 2);
  EXPECT_NE(master.output().find("master.secret_file: secret file '"), std::string::npos) << master.output();
  EXPECT_NE(master.output().find("chmod 600"), std::string::npos) << master.output();
  Process check({master_binary(), "check-config", wall.config}, wall.dir + "/check.log");
  EXPECT_EQ(check.wait(20s).value_or(-1), 2);
  EXPECT_NE(check.output().find("readable by its group and other users"), std::string::npos) << check.output();
}

// Every kind of bad peer, while two healthy nodes run at 30 Hz for 12 s: each is refused
// (logged once with its address), and the healthy nodes keep their frame rate.
TEST(Security, IntrudersAreRefusedAndHealthyNodesKeepTheirFrameRate) {
  // The attacked run: 360 frames (12 s; the attacks take about 8). The
  // undisturbed one needs no room for attacks: 120 frames give its rate.
  const auto achieved_rate = [](const std::function<void(const std::string& port, const net::Secret&)>& attack,
                                std::uint64_t* refused, std::string* log) {
    const SecretWall wall(0600, "30");
    const std::uint64_t frames = attack ? 360 : 120;
    ExternalMaster master(wall.config, {"--frames", std::to_string(frames)});
    EXPECT_FALSE(master.port.empty()) << master.process->output();
    auto left = master.node("left", {"--renderer", "null", "--secret-file", wall.secret_file});
    auto right = master.node("right", {"--renderer", "null", "--secret-file", wall.secret_file});
    EXPECT_TRUE(master.process->wait_for_output("starting frames", 20s)) << master.process->output();
    if (attack) attack(master.port, wall.secret);
    EXPECT_EQ(master.process->wait(60s).value_or(-1), 0) << master.process->output();
    const ClusterRun run = read_cluster_run(master.dir + "/out");
    EXPECT_TRUE(run.error.empty()) << run.error;
    *refused = run.report.connections_refused();
    *log = master.process->output();
    EXPECT_EQ(find_node(run.report, "left")->frames_presented(), frames);
    EXPECT_EQ(find_node(run.report, "right")->frames_presented(), frames);
    return run.report.sync().achieved_frame_rate();
  };

  std::uint64_t quiet_refused = 0;
  std::string quiet_log;
  const double undisturbed = achieved_rate({}, &quiet_refused, &quiet_log);
  EXPECT_EQ(quiet_refused, 0u);

  std::size_t attempts = 0;
  const auto attack = [&](const std::string& port, const net::Secret& secret) {
    // A replayed hello: a mac made for another connection's challenge.
    RawClient first("127.0.0.1", port);
    auto first_challenge = first.receive();
    ASSERT_TRUE(first_challenge && first_challenge->has_challenge());
    const std::string recorded = mac_text(secret, first_challenge->challenge().nonce(), "left");
    RawClient replay("127.0.0.1", port);
    ASSERT_TRUE(replay.receive().has_value());
    replay.send(hello("left", recorded));
    auto answer = replay.receive();
    ASSERT_TRUE(answer && answer->has_refuse()) << "a replayed hello must be refused";
    EXPECT_NE(answer->refuse().reason().find("authentication failed"), std::string::npos);
    ++attempts;
    // A wrong secret.
    RawClient wrong("127.0.0.1", port);
    auto challenge = wrong.receive();
    ASSERT_TRUE(challenge.has_value());
    net::Secret other{bytes_of("not the installation's secret")};
    wrong.send(hello("right", mac_text(other, challenge->challenge().nonce(), "right")));
    answer = wrong.receive();
    ASSERT_TRUE(answer && answer->has_refuse());
    ++attempts;
    // An oversized length, garbage, and a truncated frame.
    RawClient oversized("127.0.0.1", port);
    oversized.send_bytes({0x7f, 0xff, 0xff, 0xff, 1, 2, 3});
    EXPECT_TRUE(oversized.closed_within(scaled(3s)));
    RawClient garbage("127.0.0.1", port);
    garbage.send_bytes({0, 0, 0, 8, 0xde, 0xad, 0xbe, 0xef, 0xde, 0xad, 0xbe, 0xef});
    EXPECT_TRUE(garbage.closed_within(scaled(3s)));
    RawClient truncated("127.0.0.1", port);
    truncated.send_bytes({0, 0, 1, 0, 0x08, 0x04});  // promises 256 bytes, sends 2, then nothing
    EXPECT_TRUE(truncated.closed_within(scaled(3s))) << "a stalled frame must hit the handshake timeout (2 s)";
    attempts += 3;
    // One byte a second: closed within the 2 s handshake timeout all the same.
    RawClient drip("127.0.0.1", port);
    const auto started = std::chrono::steady_clock::now();
    bool closed = false;
    for (int i = 0; i < 4 * static_cast<int>(timing_scale()) && !closed; ++i) {
      drip.send_bytes({0});
      closed = drip.closed_within(1s);
    }
    EXPECT_TRUE(closed);
    EXPECT_LT(std::chrono::steady_clock::now() - started, scaled(3500ms));
    ++attempts;
    // 200 rapid connects that say nothing.
    std::vector<std::unique_ptr<RawClient>> crowd;
    for (int i = 0; i < 200; ++i) {
      crowd.push_back(std::make_unique<RawClient>("127.0.0.1", port));
      EXPECT_TRUE(crowd.back()->connected());
    }
    attempts += 200;
    std::this_thread::sleep_for(scaled(2500ms));  // past the handshake timeout: every one closed
    std::size_t closed_crowd = 0;
    for (const auto& client : crowd) closed_crowd += client->closed_within(10ms) ? 1 : 0;
    EXPECT_EQ(closed_crowd, crowd.size());
  };
  std::uint64_t refused = 0;
  std::string log;
  const double disturbed = achieved_rate(attack, &refused, &log);
  std::cout << "healthy nodes at " << undisturbed << " Hz undisturbed, " << disturbed << " Hz under attack; " << refused
            << " connections refused of " << attempts + 1 << " bad ones\n";
  // Measured (20 runs): 29.998-30.0002 Hz either way, within 0.007 %. The bar is the
  // README's 0.1 % (a stall the attack causes would cost the frames it delays:
  // the master does not catch up), loosened with the other lateness bounds
  // under the sanitizers.
  EXPECT_GE(disturbed, undisturbed * (1.0 - 0.001 * timing_scale()));
  // Every bad connection refused, the replay's first connection (which never
  // answered its challenge) included.
  EXPECT_EQ(refused, attempts + 1);
  EXPECT_NE(log.find("refused node 'left' from 127.0.0.1:"), std::string::npos);
  EXPECT_NE(log.find("frame of 2147483647 bytes"), std::string::npos) << log;
}

// Without a secret only loopback peers are accepted: a connection to this
// machine's own non-loopback address is refused (skipped where there is none).
TEST(Security, WithoutASecretOnlyLoopbackPeersAreAccepted) {
  std::string address;
  ifaddrs* interfaces = nullptr;
  if (getifaddrs(&interfaces) == 0) {
    for (ifaddrs* i = interfaces; i != nullptr && address.empty(); i = i->ifa_next) {
      if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET) continue;
      const auto* in = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
      char text[INET_ADDRSTRLEN];
      inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
      if (std::string(text).rfind("127.", 0) != 0) address = text;
    }
    freeifaddrs(interfaces);
  }
  if (address.empty()) GTEST_SKIP() << "this machine has no non-loopback IPv4 address";
  const std::string config = kConfigs + "/single-wall.json";
  const ScratchDir dir_scratch("optique-loopback");
  const std::string dir = dir_scratch.string();
  Process master({master_binary(), "--config", config, "--listen", "0.0.0.0", "--port", "0", "--port-file",
                  dir + "/port", "--frames", "60", "--no-status"},
                 dir + "/master.log");
  const std::string port = wait_for_port(dir + "/port", 10s);
  ASSERT_FALSE(port.empty()) << master.output();
  RawClient outsider(address, port);
  ASSERT_TRUE(outsider.connected());
  EXPECT_TRUE(outsider.closed_within(scaled(3s)));
  EXPECT_TRUE(master.wait_for_output("refused connection from " + address, 5s)) << master.output();
  EXPECT_NE(master.output().find("only nodes on this machine are accepted"), std::string::npos);
  // A node from "another host" is told why and stops (exit 2), as a wrong
  // secret does, instead of retrying a handshake that can never pass.
  Process node({node_binary(), "--master", address + ":" + port, "--id", "wall", "--renderer", "null"},
               dir + "/node.log");
  EXPECT_EQ(node.wait(20s).value_or(-1), 2) << node.output();
  EXPECT_NE(node.output().find("the master refused this node: no shared secret is configured"), std::string::npos)
      << node.output();
  master.signal(SIGINT);
  EXPECT_TRUE(master.wait(20s).has_value());
}

}  // namespace
}  // namespace optique::testing
