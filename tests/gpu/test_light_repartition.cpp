// An automatic stacked group end to end (configs/stacked-lighting-3-auto.json):
// three real nodes share 20 lights by cost; half the lights go dark and come back
// (scene light switches), and one node is killed. Each time the master must share
// the lights that shine out anew, at one frame, among the nodes that are up —
// every shining light drawn exactly once — and the screen must show it: the
// composite matches render-reference while lights are off, and after the kill the
// two survivors' light alone matches it, where before the kill it lacked the
// killed node's lights. And a light an application adds is shared out in the
// frame it lands in, drawn once, and on the screen. Label `gpu`.

#include <gtest/gtest.h>

#include <csignal>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "clients/cpp/session.h"
#include "config/light_list.h"
#include "image/frame_files.h"
#include "process.h"
#include "screen_check.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kNode = std::string(OPTIQUE_BIN_DIR) + "/optique-node";
const std::string kConfig = std::string(OPTIQUE_SOURCE_DIR) + "/configs/stacked-lighting-3-auto.json";
const std::vector<std::string> kNodes{"lights-a", "lights-b", "lights-hd"};
const std::string kKilled = "lights-b";
constexpr std::uint64_t kFrames = 40;
constexpr std::uint64_t kCaptureEvery = 2;
// At 5 Hz: lights 10-19 are off for frames 10-19.
constexpr std::uint64_t kDarkFrom = 10;
constexpr std::uint64_t kLitAgainFrom = 20;
constexpr std::uint64_t kKillAfter = 26;  // the killed node's capture of this frame exists

struct LoggedShare {
  std::uint64_t from = 0;
  std::set<std::uint32_t> lights;
  bool ambient = false;
};

// "node 'X' draws lights [L] and ambient from frame N", in log order, by node;
// and where in the log the killed node left.
struct ShareLog {
  std::map<std::string, std::vector<LoggedShare>> shares;
  std::uint64_t first_after_leaving = 0;  // the first frame of a share logged after the node left
};

ShareLog parse_share_log(const std::string& log) {
  ShareLog parsed;
  const std::regex share_line(R"(node '([\w-]+)' draws lights \[([^\]]*)\]( and ambient)? from frame (\d+))");
  bool left = false;
  std::istringstream lines(log);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("node '" + kKilled + "' left") != std::string::npos) left = true;
    std::smatch m;
    if (!std::regex_search(line, m, share_line)) continue;
    auto lights = config::parse_light_list(m[2].str());
    EXPECT_TRUE(lights) << line;
    LoggedShare share{std::stoull(m[4].str()), {}, m[3].matched};
    if (lights) share.lights.insert(lights.value().begin(), lights.value().end());
    if (left && parsed.first_after_leaving == 0) parsed.first_after_leaving = share.from;
    parsed.shares[m[1].str()].push_back(std::move(share));
  }
  return parsed;
}

// The share each node draws at `frame`: the last one logged from that frame or before.
struct Drawn {
  std::multiset<std::uint32_t> lights;
  int ambient_carriers = 0;
};

Drawn drawn_at(const ShareLog& log, std::uint64_t frame, const std::vector<std::string>& nodes) {
  Drawn drawn;
  for (const std::string& node : nodes) {
    const LoggedShare* current = nullptr;
    if (const auto found = log.shares.find(node); found != log.shares.end()) {
      for (const LoggedShare& share : found->second) {
        if (share.from <= frame) current = &share;
      }
    }
    if (current == nullptr) {
      ADD_FAILURE() << "no share logged for '" << node << "' by frame " << frame;
      continue;
    }
    drawn.lights.insert(current->lights.begin(), current->lights.end());
    drawn.ambient_carriers += current->ambient ? 1 : 0;
  }
  return drawn;
}

std::multiset<std::uint32_t> range(std::uint32_t first, std::uint32_t last) {
  std::multiset<std::uint32_t> lights;
  for (std::uint32_t i = first; i <= last; ++i) lights.insert(i);
  return lights;
}

// The group's config at 5 Hz, with a frame timeout for captures on a shared
// software rasterizer, its scene's light switches as `switches` sets them;
// written to `path`.
std::string slow_config(const std::string& path, const std::function<void(schema::Scene&)>& switches) {
  return write_config_variant(
      kConfig,
      [&](schema::Installation& installation) {
        installation.mutable_master()->set_frame_rate(5.0);
        installation.mutable_master()->set_frame_timeout_ms(5000);
        switches(*installation.mutable_scene());
      },
      path);
}

TEST(LightRepartition, LightsSwitchedAndANodeKilledAreSharedOutAnewAndTheScreenShowsIt) {
  const ScratchDir dir_scratch("optique-repartition");
  const std::string dir = dir_scratch.string();
  const std::string config = slow_config(dir + "/auto.json", [](schema::Scene& scene) {
    auto& switches = *scene.mutable_light_switches();
    switches.Clear();
    auto* off = switches.Add();
    off->set_time(2.0);
    off->set_off("10-19");
    auto* on = switches.Add();
    on->set_time(4.0);
    on->set_on("10-19");
  });
  const std::string out = dir + "/out";
  Process master(
      {kMaster, "--config", config, "--listen", "127.0.0.1", "--port", "0", "--port-file", dir + "/port", "--out", out,
       "--frames", std::to_string(kFrames), "--capture-every", std::to_string(kCaptureEvery), "--no-status"},
      dir + "/master.log");
  const std::string port = wait_for_port(dir + "/port", 10s);
  ASSERT_FALSE(port.empty()) << master.output();
  std::map<std::string, std::unique_ptr<Process>> nodes;
  for (const std::string& id : kNodes) {
    nodes[id] = std::make_unique<Process>(std::vector<std::string>{kNode, "--master", "127.0.0.1:" + port, "--id", id,
                                                                   "--capture-dir", out + "/nodes/" + id},
                                          dir + "/node-" + id + ".log");
  }
  const std::string killed_capture = image::frame_path(out + "/nodes/" + kKilled, kKillAfter, "png");
  ASSERT_TRUE(wait_for_file(killed_capture, 120s)) << master.output();
  nodes.at(kKilled)->signal(SIGKILL);
  ASSERT_EQ(master.wait(120s).value_or(-1), 0) << master.output();
  for (const std::string& id : kNodes) {
    if (id != kKilled) {
      EXPECT_EQ(nodes.at(id)->wait(30s).value_or(-1), 0) << nodes.at(id)->output();
    }
  }

  const std::string log = master.output();
  EXPECT_NE(log.find("frame 10: lights [10-19] go dark (10 of 20 off)"), std::string::npos) << log;
  EXPECT_NE(log.find("frame 20: lights [10-19] come on (0 of 20 off)"), std::string::npos) << log;
  const ShareLog shares = parse_share_log(log);
  for (std::uint64_t frame : {std::uint64_t{0}, kDarkFrom - 1, kLitAgainFrom, kKillAfter}) {
    const Drawn drawn = drawn_at(shares, frame, kNodes);
    EXPECT_EQ(drawn.lights, range(0, 19)) << "frame " << frame << ": every light once";
    EXPECT_EQ(drawn.ambient_carriers, 1) << "frame " << frame;
  }
  for (std::uint64_t frame = kDarkFrom; frame < kLitAgainFrom; ++frame) {
    const Drawn drawn = drawn_at(shares, frame, kNodes);
    EXPECT_EQ(drawn.lights, range(0, 9)) << "frame " << frame << ": only the lights that shine, each once";
    EXPECT_EQ(drawn.ambient_carriers, 1) << "frame " << frame;
  }
  ASSERT_GT(shares.first_after_leaving, kKillAfter) << "no new share after '" << kKilled << "' left:\n" << log;
  ASSERT_LT(shares.first_after_leaving, kFrames - kCaptureEvery) << log;
  const std::vector<std::string> survivors{"lights-a", "lights-hd"};
  const Drawn after = drawn_at(shares, shares.first_after_leaving, survivors);
  EXPECT_EQ(after.lights, range(0, 19)) << "the survivors draw every light once";
  EXPECT_EQ(after.ambient_carriers, 1);
  EXPECT_FALSE(drawn_at(shares, kKillAfter, {kKilled}).lights.empty()) << "the killed node drew lights before";

  // On the screen. All three while half the lights are off:
  const ScreenCheck three{kMaster, config, out + "/nodes", out, "front"};
  const ScreenMatch dark = compare_with_reference(three, kDarkFrom + 2);
  std::cout << "frame " << kDarkFrom + 2 << ", lights 10-19 off, three nodes: " << dark.psnr_db << " dB, "
            << dark.pixels_off << " px off by > 1 %\n";
  EXPECT_GE(dark.psnr_db, 45.0);
  // The two survivors alone, before the kill (the killed node's lights missing) and after:
  const std::string two_config = write_config_variant(
      config,
      [](schema::Installation& installation) {
        auto& projectors = *installation.mutable_projectors();
        for (int i = 0; i < projectors.size(); ++i) {
          if (projectors.Get(i).id() == kKilled) projectors.DeleteSubrange(i, 1);
        }
      },
      dir + "/survivors.json");
  const ScreenCheck two{kMaster, two_config, out + "/nodes", dir + "/survivors", "front"};
  const std::uint64_t after_frame = (shares.first_after_leaving + kCaptureEvery - 1) / kCaptureEvery * kCaptureEvery;
  const ScreenMatch before_kill = compare_with_reference(two, kKillAfter);
  const ScreenMatch after_kill = compare_with_reference(two, after_frame);
  std::cout << "the survivors' light alone: frame " << kKillAfter << " (before the kill) " << before_kill.psnr_db
            << " dB, " << before_kill.pixels_off << " px off; frame " << after_frame << " (shared out anew) "
            << after_kill.psnr_db << " dB, " << after_kill.pixels_off << " px off\n";
  EXPECT_GE(after_kill.psnr_db, 45.0);
  EXPECT_LT(before_kill.psnr_db, after_kill.psnr_db - 10.0) << "the killed node's lights were missing before";
  EXPECT_GT(before_kill.pixels_off, 10 * std::max<std::size_t>(after_kill.pixels_off, 1));
}

// An application adds a light to the automatic group while it runs: the
// master shares it out in the frame the reply names (every light, the new one
// included, drawn once), and the composite of the three nodes matches the
// reference drawn from the session's journal, which the reference without the
// light does not.
TEST(LightRepartition, ALightAnApplicationAddsIsSharedOutAndTheScreenShowsIt) {
  const ScratchDir dir_scratch("optique-added-light");
  const std::string dir = dir_scratch.string();
  const std::string config =
      slow_config(dir + "/auto.json", [](schema::Scene& scene) { scene.clear_light_switches(); });
  const std::string out = dir + "/out";
  const std::string journal = dir + "/session.journal";
  constexpr std::uint64_t kRun = 24;
  Process master({kMaster, "--config", config, "--local", "--out", out, "--frames", std::to_string(kRun),
                  "--capture-every", std::to_string(kCaptureEvery), "--no-status", "--api-port", "0", "--api-port-file",
                  dir + "/api.port", "--record", journal},
                 dir + "/master.log");
  ASSERT_TRUE(wait_for_file(dir + "/api.port", 60s)) << master.output();
  client::Options options;
  options.port = static_cast<std::uint16_t>(std::stoi(read_file(dir + "/api.port")));
  options.name = "lamp";
  auto session = client::Session::connect(options);
  ASSERT_TRUE(session.ok()) << session.error();
  client::Session& app = *session.value();
  ASSERT_EQ(app.scene().light_count(), 20u);
  session::Subscribe frames;
  frames.set_frames(true);
  ASSERT_TRUE(app.subscribe(frames).ok());
  for (std::uint64_t begun = 0; begun < 4;) {  // a few frames in, every node drawing
    auto event = app.next_event(60s);
    ASSERT_TRUE(event.ok() && event.value().has_value()) << master.output();
    if (event.value()->has_frame_begun()) begun = event.value()->frame_begun().frame();
  }
  // Warm, in front of the middle of the screen: it lights what the 20 do not.
  auto added = app.apply(client::Transaction().point_light(20, {{0.2, 1.0, 0.7}}, {{1.0, 0.7, 0.4}}, 0.6));
  ASSERT_TRUE(added.ok() && added.value().applied()) << (added.ok() ? "refused" : added.error());
  const std::uint64_t from = added.value().frame;
  app.close();
  ASSERT_EQ(master.wait(120s).value_or(-1), 0) << master.output();
  ASSERT_LT(from, kRun - 2 * kCaptureEvery) << master.output();

  const std::string log = master.output();
  EXPECT_NE(log.find("frame " + std::to_string(from) + ": lights [20] added or changed"), std::string::npos) << log;
  const ShareLog shares = parse_share_log(log);
  EXPECT_EQ(drawn_at(shares, from - 1, kNodes).lights, range(0, 19)) << "before: the scene's 20";
  const Drawn with = drawn_at(shares, from, kNodes);
  EXPECT_EQ(with.lights, range(0, 20)) << "from frame " << from << ": the added one too, each once";
  EXPECT_EQ(with.ambient_carriers, 1);

  const std::uint64_t shown = (from + kCaptureEvery) / kCaptureEvery * kCaptureEvery;  // a captured frame after
  const ScreenCheck lit{kMaster, config, out + "/nodes", dir + "/lit", "front", {"--replay", journal}};
  const ScreenMatch match = compare_with_reference(lit, shown);
  const ScreenCheck unlit{kMaster, config, out + "/nodes", dir + "/unlit", "front"};
  const ScreenMatch without = compare_with_reference(unlit, shown);
  std::cout << "frame " << shown << ", light 20 added in frame " << from << ": against the journal's reference "
            << match.psnr_db << " dB, " << match.pixels_off << " px off by > 1 %; against the scene without it "
            << without.psnr_db << " dB, " << without.pixels_off << " px off\n";
  EXPECT_GE(match.psnr_db, 45.0);
  EXPECT_LT(without.psnr_db, match.psnr_db - 10.0) << "the light shows on the screen";
  EXPECT_GT(without.pixels_off, 10 * std::max<std::size_t>(match.pixels_off, 1));
}

}  // namespace
}  // namespace optique::testing
