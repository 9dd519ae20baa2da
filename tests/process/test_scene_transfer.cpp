// A glTF scene reaches the nodes from the master (real processes, GL nodes on
// llvmpipe): a node with an empty cache fetches it and a restarted one does not;
// a chunk spoilt on the way (the fault proxy) is refused and fetched again; the
// master sends what it loaded, not what its disk holds later; and a node on
// another host — a network namespace, the master with the shared secret — fetches
// it and draws the same capture as a node that had it.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "external_master.h"
#include "fault_proxy.h"
#include "image/compare.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "process.h"

namespace optique::testing {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const std::string kTorus = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/";
constexpr int kFrames = 12;
constexpr std::uint64_t kCapturedFrame = 10;

// The torus with its files beside it, copied to `dir`/scene/; with `big_bytes`,
// a second buffer of that many bytes (unused by the mesh, but part of the scene),
// so that the transfer takes several chunks.
std::string torus_scene(const std::string& dir, std::size_t big_bytes = 0) {
  const fs::path scene = fs::path(dir) / "scene";
  fs::create_directories(scene);
  for (const char* name : {"torus.gltf", "torus.bin", "torus.png"}) fs::copy_file(kTorus + name, scene / name);
  if (big_bytes > 0) {
    std::string big(big_bytes, '\0');
    for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>((i * 2654435761u) >> 13);
    std::ofstream(scene / "big.bin", std::ios::binary) << big;
    std::ifstream in(scene / "torus.gltf");
    nlohmann::json gltf = nlohmann::json::parse(in);
    gltf["buffers"].push_back({{"uri", "big.bin"}, {"byteLength", big_bytes}});
    std::ofstream(scene / "torus.gltf") << gltf.dump(1);
  }
  return (scene / "torus.gltf").string();
}

// configs/gltf-torus.json showing `gltf`, the master on `listen`, with the shared
// secret in `dir`/secret when `secret`.
std::string torus_config(const std::string& dir, const std::string& gltf, const std::string& listen, bool secret) {
  std::ifstream in(std::string(OPTIQUE_SOURCE_DIR) + "/configs/gltf-torus.json");
  nlohmann::json config = nlohmann::json::parse(in);
  config["scene"]["gltf"] = gltf;
  config["master"]["listen"] = listen;
  config["master"]["port"] = 0;
  if (secret) {
    std::ofstream(dir + "/secret") << "a secret only this installation knows\n";
    chmod((dir + "/secret").c_str(), 0600);
    config["master"]["secret_file"] = "secret";
  }
  const std::string path = dir + "/torus.json";
  std::ofstream(path) << config.dump(1);
  return path;
}

struct ClusterOutcome {
  std::string master_log;
  std::string node_log;
  int master_status = -1;
  int node_status = -1;
  image::FloatImage capture;
};

// A master running `config` for kFrames frames and one GL node for 'wall' with
// `cache` as its cache folder, started with `prefix` (ip netns exec …),
// connecting to `host`:the master's port, with the secret beside the config when
// `secret`; `before_node` runs once the master is listening.
ClusterOutcome run(const std::string& config, const std::string& cache, const std::string& host,
                   const std::vector<std::string>& prefix = {}, bool secret = false,
                   const std::function<void()>& before_node = {}) {
  const ScratchDir dir_scratch("optique-transfer-run");
  const std::string dir = dir_scratch.string();
  Process master(
      {master_binary(), "--config", config, "--port-file", dir + "/port", "--frames", std::to_string(kFrames),
       "--capture-every", std::to_string(kCapturedFrame), "--no-status", "--out", dir + "/out"},
      dir + "/master.log");
  ClusterOutcome out;
  const std::string port = wait_for_port(dir + "/port", 10s);
  if (port.empty()) {
    ADD_FAILURE() << "the master wrote no port:\n" << master.output();
    return out;
  }
  if (before_node) before_node();
  std::vector<std::string> argv = prefix;
  const std::vector<std::string> node{node_binary(), "--master", host + ":" + port, "--id",           "wall",
                                      "--cache-dir", cache,      "--capture-dir",   dir + "/captures"};
  argv.insert(argv.end(), node.begin(), node.end());
  if (secret) {
    argv.push_back("--secret-file");
    argv.push_back(fs::path(config).parent_path() / "secret");
  }
  Process node_process(argv, dir + "/node.log");
  out.master_status = master.wait(scaled(60s)).value_or(-1);
  out.node_status = node_process.wait(scaled(20s)).value_or(-1);
  out.master_log = master.output();
  out.node_log = node_process.output();
  auto image = image::read_image(image::frame_path(dir + "/captures", kCapturedFrame, "png"));
  if (image) out.capture = std::move(image).value();
  return out;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

void expect_same_capture(const image::FloatImage& a, const image::FloatImage& b) {
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  auto comparison = image::compare(a, b);
  ASSERT_TRUE(comparison.ok()) << comparison.error();
  const auto& c = comparison.value();
  EXPECT_GE(std::min({c.psnr_r, c.psnr_g, c.psnr_b}), 50.0)
      << "PSNR R/G/B " << c.psnr_r << "/" << c.psnr_g << "/" << c.psnr_b;
  double lit = 0.0;
  for (float v : a.pixels) lit += v;
  EXPECT_GT(lit, 1000.0) << "the torus was drawn";
}

// The folders in the cache's scenes/: its copies, whole or partial (beside
// them, the hidden lock nodes take to begin a copy).
std::vector<fs::path> copies_in(const std::string& cache) {
  std::vector<fs::path> copies;
  for (const auto& entry : fs::directory_iterator(cache + "/scenes")) {
    if (entry.is_directory()) copies.push_back(entry.path());
  }
  return copies;
}

TEST(SceneTransfer, ANodeWithAnEmptyCacheFetchesTheSceneAndARestartedOneDoesNot) {
  const ScratchDir dir_scratch("optique-transfer");
  const std::string dir = dir_scratch.string();
  const std::string config = torus_config(dir, torus_scene(dir), "127.0.0.1", false);
  const std::string cache = dir + "/cache";
  const ClusterOutcome fetched = run(config, cache, "127.0.0.1");
  EXPECT_EQ(fetched.master_status, 0) << fetched.master_log;
  EXPECT_EQ(fetched.node_status, 0) << fetched.node_log;
  EXPECT_TRUE(contains(fetched.node_log, "fetching the scene")) << fetched.node_log;
  EXPECT_TRUE(contains(fetched.node_log, "fetched the scene: 0.2 MiB")) << fetched.node_log;
  EXPECT_TRUE(contains(fetched.master_log, "sending the scene to 'wall', which has no copy: 3 file(s)"))
      << fetched.master_log;
  EXPECT_TRUE(contains(fetched.master_log, "sent the scene to 'wall'")) << fetched.master_log;
  // The copy, under the scene's identity, holds the files as they are.
  const std::vector<fs::path> copies = copies_in(cache);
  ASSERT_EQ(copies.size(), 1u);
  EXPECT_EQ(read_file(copies[0] / "torus.png"), read_file(kTorus + "torus.png"));

  const ClusterOutcome restarted = run(config, cache, "127.0.0.1");
  EXPECT_EQ(restarted.master_status, 0) << restarted.master_log;
  EXPECT_TRUE(contains(restarted.node_log, "is here")) << restarted.node_log;
  EXPECT_FALSE(contains(restarted.node_log, "fetching the scene")) << restarted.node_log;
  EXPECT_FALSE(contains(restarted.master_log, "sending the scene")) << restarted.master_log;
  expect_same_capture(fetched.capture, restarted.capture);
}

TEST(SceneTransfer, TheMasterSendsTheFilesAsItLoadedThemNotAsTheyAreLater) {
  const ScratchDir dir_scratch("optique-transfer");
  const std::string dir = dir_scratch.string();
  const std::string gltf = torus_scene(dir);
  const std::string config = torus_config(dir, gltf, "127.0.0.1", false);
  const std::string cache = dir + "/cache";
  const std::string png = read_file(kTorus + "torus.png");
  // Once the master has loaded the scene, a byte of its texture changes on disk
  // (inside the file: a master that read it again would send other bytes).
  const ClusterOutcome fetched = run(config, cache, "127.0.0.1", {}, false, [&] {
    std::fstream file(fs::path(gltf).parent_path() / "torus.png", std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(500);
    file.put('\x7f');
  });
  EXPECT_EQ(fetched.master_status, 0) << fetched.master_log;
  EXPECT_EQ(fetched.node_status, 0) << fetched.node_log;
  const std::vector<fs::path> copies = copies_in(cache);
  ASSERT_EQ(copies.size(), 1u);
  EXPECT_EQ(read_file(copies[0] / "torus.png"), png);
}

TEST(SceneTransfer, AChunkSpoiltOnTheWayIsRefusedAndFetchedAgain) {
  const ScratchDir dir_scratch("optique-transfer");
  const std::string dir = dir_scratch.string();
  const std::size_t big = 3u << 20;
  const std::string config = torus_config(dir, torus_scene(dir, big), "127.0.0.1", false);
  const std::string cache = dir + "/cache";
  Process master({master_binary(), "--config", config, "--port-file", dir + "/port", "--frames",
                  std::to_string(kFrames), "--no-status", "--out", dir + "/out"},
                 dir + "/master.log");
  const std::string port = wait_for_port(dir + "/port", 10s);
  ASSERT_FALSE(port.empty()) << master.output();
  FaultProxy proxy(static_cast<std::uint16_t>(std::stoi(port)));
  // What the master sends: the challenge and the welcome (a few KiB), the glTF,
  // torus.bin (184 KiB), then big.bin's chunks of 1 MiB: 1.7 MiB in is the
  // middle of big.bin's second chunk, far from any message's framing.
  proxy.corrupt_from_target_at((17u << 20) / 10);
  Process node(
      {node_binary(), "--master", "127.0.0.1:" + std::to_string(proxy.port()), "--id", "wall", "--cache-dir", cache},
      dir + "/node.log");
  EXPECT_EQ(master.wait(scaled(60s)), 0) << master.output();
  EXPECT_EQ(node.wait(scaled(20s)), 0) << node.output();
  EXPECT_EQ(proxy.corruptions_done(), 1u);
  EXPECT_TRUE(contains(node.output(), "chunk 1 of file 2 ('big.bin') does not match its SHA-256; asking for it again"))
      << node.output();
  EXPECT_TRUE(contains(node.output(), "1 chunk(s) asked for again")) << node.output();
  EXPECT_TRUE(contains(master.output(), "'wall' asked again for chunk 1 of 'big.bin' of the scene")) << master.output();
  EXPECT_TRUE(contains(master.output(), "node 'wall' joined")) << master.output();
  const std::vector<fs::path> copies = copies_in(cache);
  ASSERT_EQ(copies.size(), 1u);
  EXPECT_EQ(read_file(copies[0] / "big.bin"), read_file(fs::path(dir) / "scene/big.bin"));
}

// Two nodes of one host sharing one cache fetch the scene once: the first
// (through a proxy that holds each piece 300 ms while it fetches, so that the
// fetch lasts) fetches,
// the second waits for its copy, and both draw.
TEST(SceneTransfer, TwoNodesOfOneHostSharingACacheFetchTheSceneOnce) {
  const ScratchDir dir_scratch("optique-transfer");
  const std::string dir = dir_scratch.string();
  const std::string config_path = torus_config(dir, torus_scene(dir, 6u << 20), "127.0.0.1", false);
  {
    std::ifstream in(config_path);
    nlohmann::json config = nlohmann::json::parse(in);
    nlohmann::json left = config["projectors"][0];
    left["width"] = 320;
    left["region"] = {{"x", 0.0}, {"y", 0.0}, {"width", 1.0}, {"height", 1.125}};
    nlohmann::json right = left;
    right["id"] = "wall-b";
    right["region"]["x"] = 1.0;
    config["projectors"] = {left, right};
    std::ofstream(config_path) << config.dump(1);
  }
  const std::string cache = dir + "/cache";
  Process master({master_binary(), "--config", config_path, "--port-file", dir + "/port", "--frames",
                  std::to_string(kFrames), "--no-status", "--out", dir + "/out"},
                 dir + "/master.log");
  const std::string port = wait_for_port(dir + "/port", 10s);
  ASSERT_FALSE(port.empty()) << master.output();
  FaultProxy proxy(static_cast<std::uint16_t>(std::stoi(port)));
  proxy.set_delay(300ms, 0us);
  Process first(
      {node_binary(), "--master", "127.0.0.1:" + std::to_string(proxy.port()), "--id", "wall", "--cache-dir", cache},
      dir + "/first.log");
  ASSERT_TRUE(first.wait_for_output("fetching the scene", scaled(10s))) << first.output();
  Process second({node_binary(), "--master", "127.0.0.1:" + port, "--id", "wall-b", "--cache-dir", cache},
                 dir + "/second.log");
  // Its fetch done, the first keeps up with the frames: no more delay.
  EXPECT_TRUE(first.wait_for_output("fetched the scene", scaled(30s))) << first.output();
  proxy.set_delay(0us, 0us);
  EXPECT_EQ(master.wait(scaled(60s)), 0) << master.output();
  EXPECT_EQ(first.wait(scaled(20s)), 0) << first.output();
  EXPECT_EQ(second.wait(scaled(20s)), 0) << second.output();
  EXPECT_TRUE(contains(second.output(), "another node of this host is fetching the scene")) << second.output();
  EXPECT_TRUE(contains(second.output(), "fetched by another node of this host")) << second.output();
  EXPECT_FALSE(contains(second.output(), "fetching the scene from the master")) << second.output();
  EXPECT_TRUE(contains(master.output(), "sending the scene to 'wall', which has no copy")) << master.output();
  EXPECT_FALSE(contains(master.output(), "sending the scene to 'wall-b'")) << master.output();
  EXPECT_TRUE(contains(master.output(), "'wall-b' waits for the copy of the scene")) << master.output();
  EXPECT_TRUE(contains(master.output(), "node 'wall-b' joined")) << master.output();
  EXPECT_EQ(copies_in(cache).size(), 1u);
}

// Two network namespaces' worth of hosts on this machine: the master's side of a
// veth pair in this namespace (10.213.N.1), the node's in a namespace of its own
// (10.213.N.2). Needs root (CAP_NET_ADMIN), as CI has; skipped where not.
class OtherHost {
 public:
  OtherHost() : name_("optique-host-" + std::to_string(getpid())) {
    const std::string n = std::to_string(getpid() % 200 + 20);
    master_address_ = "10.213." + n + ".1";
    const std::string veth = "oq" + std::to_string(getpid());
    veth_ = veth;
    const std::vector<std::string> setup{
        "ip netns add " + name_,
        "ip link add " + veth + "a type veth peer name " + veth + "b",
        "ip link set " + veth + "b netns " + name_,
        "ip addr add " + master_address_ + "/24 dev " + veth + "a",
        "ip link set " + veth + "a up",
        "ip netns exec " + name_ + " ip addr add 10.213." + n + ".2/24 dev " + veth + "b",
        "ip netns exec " + name_ + " ip link set " + veth + "b up",
        "ip netns exec " + name_ + " ip link set lo up",
    };
    for (const std::string& command : setup) {
      if (std::system((command + " 2>/dev/null").c_str()) != 0) {
        problem_ = "'" + command + "' failed (network namespaces need root)";
        return;
      }
    }
  }
  ~OtherHost() {
    (void)std::system(("ip link del " + veth_ + "a 2>/dev/null").c_str());
    (void)std::system(("ip netns del " + name_ + " 2>/dev/null").c_str());
  }
  OtherHost(const OtherHost&) = delete;
  OtherHost& operator=(const OtherHost&) = delete;

  [[nodiscard]] const std::string& problem() const { return problem_; }
  [[nodiscard]] const std::string& master_address() const { return master_address_; }
  [[nodiscard]] std::vector<std::string> prefix() const { return {"/usr/sbin/ip", "netns", "exec", name_}; }

 private:
  std::string name_;
  std::string veth_;
  std::string master_address_;
  std::string problem_;
};

TEST(SceneTransfer, ANodeOnAnotherHostWithTheSecretFetchesTheSceneAndDrawsWhatANodeThatHadItDraws) {
  const OtherHost host;
  if (!host.problem().empty()) GTEST_SKIP() << host.problem();
  const ScratchDir dir_scratch("optique-transfer");
  const std::string dir = dir_scratch.string();
  const std::string config = torus_config(dir, torus_scene(dir), host.master_address(), true);
  const std::string cache = dir + "/cache";
  const ClusterOutcome fetched = run(config, cache, host.master_address(), host.prefix(), true);
  EXPECT_EQ(fetched.master_status, 0) << fetched.master_log;
  EXPECT_EQ(fetched.node_status, 0) << fetched.node_log;
  EXPECT_TRUE(contains(fetched.node_log, "fetched the scene")) << fetched.node_log;
  EXPECT_TRUE(contains(fetched.master_log, "node 'wall' joined from " + host.master_address().substr(0, 9)))
      << fetched.master_log;
  const ClusterOutcome had_it = run(config, cache, host.master_address(), host.prefix(), true);
  EXPECT_TRUE(contains(had_it.node_log, "is here")) << had_it.node_log;
  expect_same_capture(fetched.capture, had_it.capture);
}

}  // namespace
}  // namespace optique::testing
