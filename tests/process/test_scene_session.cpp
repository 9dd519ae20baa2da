// The scene session on a real master with real local nodes: an application
// connects to master.api over TCP, says hello, and its transactions are
// answered with the frame from which every node shows them, or refused with
// the field and why; the nodes' states keep the master's hash throughout.

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/time.h>

#include <boost/asio.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cluster_run.h"
#include "net/envelope.h"
#include "net/framing.h"
#include "process.h"
#include "scratch.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;
namespace asio = boost::asio;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

// A blocking application: one envelope out, one in.
class Application {
 public:
  explicit Application(int port) : socket_(io_) {
    socket_.connect({asio::ip::make_address("127.0.0.1"), static_cast<std::uint16_t>(port)});
    // A master that does not answer fails the test, not hangs it.
    const timeval timeout{10, 0};
    setsockopt(socket_.native_handle(), SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  void send(wire::Envelope message) {
    message.set_protocol_version(net::kProtocolVersion);
    message.set_sequence(next_sequence_++);
    std::vector<std::uint8_t> bytes;
    net::append_envelope(bytes, message);
    asio::write(socket_, asio::buffer(bytes));
  }
  wire::Envelope receive() {
    for (;;) {
      net::DecodedFrame frame = reader_.next();
      if (frame.status == net::DecodeStatus::good) {
        auto envelope = net::parse_envelope(frame.payload);
        EXPECT_TRUE(envelope) << (envelope ? "" : envelope.error());
        return envelope ? envelope.value() : wire::Envelope{};
      }
      if (frame.status == net::DecodeStatus::bad) return {};
      std::array<std::uint8_t, 4096> chunk{};
      boost::system::error_code ec;
      const std::size_t got = socket_.read_some(asio::buffer(chunk), ec);
      if (ec) return {};
      reader_.append(std::span(chunk.data(), got));
    }
  }

 private:
  asio::io_context io_;
  asio::ip::tcp::socket socket_;
  net::FrameReader reader_;
  std::uint64_t next_sequence_ = 1;
};

wire::Envelope hello(const std::string& name) {
  wire::Envelope e;
  e.mutable_hello()->set_node_id(name);
  e.mutable_hello()->add_capabilities("scene-session");
  return e;
}

wire::Envelope create(std::uint64_t id, const std::string& instance, const std::string& asset, double x) {
  wire::Envelope e;
  e.mutable_session_request()->set_id(id);
  auto& c = *e.mutable_session_request()->mutable_transaction()->add_edits()->mutable_create();
  c.set_instance(instance);
  c.set_asset(asset);
  c.mutable_transform()->add_position(x);
  c.mutable_transform()->add_position(1.0);
  c.mutable_transform()->add_position(0.0);
  return e;
}

TEST(SceneSession, AnApplicationPlacesAnInstanceAndEveryNodeShowsItFromTheFrameNamed) {
  ScratchDir dir("optique-session");
  // The power wall with the scene session on an ephemeral port.
  auto config = nlohmann::json::parse(std::ifstream(kConfigs + "/powerwall-2x2.json"));
  config["master"]["api"] = {{"port", 0}};
  config["master"]["port"] = 0;
  std::ofstream(dir.file("wall.json")) << config.dump(2);
  Process master({kMaster, "--config", dir.file("wall.json"), "--local", "--frames", "240", "--out", dir.file("out"),
                  "--no-status", "--node-arg=--renderer=null", "--api-port-file", dir.file("api.port")},
                 dir.file("master.log"));
  ASSERT_TRUE(wait_for_file(dir.file("api.port"), 15s)) << master.output();
  Application app(std::stoi(read_file(dir.file("api.port"))));

  const wire::Envelope challenge = app.receive();
  ASSERT_TRUE(challenge.has_challenge()) << master.output();
  EXPECT_FALSE(challenge.challenge().secret_required());
  app.send(hello("wall-test"));
  ASSERT_TRUE(master.wait_for_output("application 'wall-test' connected from 127.0.0.1", 10s)) << master.output();

  app.send(create(1, "c1", "cubes", 0.5));
  const wire::Envelope applied = app.receive();
  ASSERT_TRUE(applied.has_session_reply()) << master.output();
  EXPECT_EQ(applied.session_reply().id(), 1u);
  ASSERT_TRUE(applied.session_reply().has_applied()) << applied.session_reply().refused().reason();
  EXPECT_LT(applied.session_reply().applied().frame(), 240u);

  app.send(create(2, "c2", "teapot", 0.0));
  const wire::Envelope refused = app.receive();
  ASSERT_TRUE(refused.session_reply().has_refused());
  EXPECT_EQ(refused.session_reply().id(), 2u);
  EXPECT_EQ(refused.session_reply().refused().field(), "edits[0].create.asset");
  EXPECT_EQ(refused.session_reply().refused().reason(), "no asset 'teapot' is loaded");

  // The run ends in order, the application is told goodbye, and no node's
  // state left the master's: the instance was in every node's delta.
  ASSERT_EQ(master.wait(60s), 0) << master.output();
  EXPECT_TRUE(app.receive().has_goodbye());
  const ClusterRun run = read_cluster_run(dir.file("out"));
  ASSERT_EQ(run.error, "");
  EXPECT_EQ(run.report.frames(), 240u);
  ASSERT_EQ(run.report.nodes_size(), 4);
  for (const auto& node : run.report.nodes()) EXPECT_EQ(node.hash_mismatches(), 0u) << node.id();
  EXPECT_EQ(run.report.instances(), 1u) << "the instance is in the last frame's state";
}

}  // namespace
}  // namespace optique::testing
