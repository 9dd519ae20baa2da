// The operator's page and metrics of a real master with real local nodes, as an
// operator and a site's monitoring use them: Debian's headless Chromium opens
// the page and must see every node up and the frame counter advance (the
// screenshot is kept), Debian's promtool must accept /metrics, and the bearer
// token guards the data beyond loopback and every control.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "cluster_run.h"
#include "headless_chromium.h"
#include "http_client.h"
#include "process.h"
#include "websocket_client.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

// A master with local null nodes and its status server on an ephemeral port.
struct StatusRun {
  ScratchDir dir_scratch{"optique-status"};
  const std::string dir = dir_scratch.string();
  std::unique_ptr<Process> master;
  int port = 0;

  StatusRun(const std::string& config, const std::string& frames, const std::vector<std::string>& more = {}) {
    std::vector<std::string> argv{kMaster,
                                  "--config",
                                  config,
                                  "--local",
                                  "--frames",
                                  frames,
                                  "--out",
                                  dir + "/out",
                                  "--no-status",
                                  "--node-arg=--renderer=null",
                                  "--status-port",
                                  "0",
                                  "--status-port-file",
                                  dir + "/status.port"};
    argv.insert(argv.end(), more.begin(), more.end());
    master = std::make_unique<Process>(argv, dir + "/master.log");
    if (wait_for_file(dir + "/status.port", 15s)) port = std::stoi(read_file(dir + "/status.port"));
  }
  [[nodiscard]] nlohmann::json status(const std::string& token = "") const {
    const HttpReply reply = http_request(port, "GET", "/status.json", token);
    EXPECT_EQ(reply.status, 200) << reply.error << reply.body;
    return reply.status == 200 ? nlohmann::json::parse(reply.body, nullptr, false) : nlohmann::json();
  }
  // Polls /status.json until `done` holds.
  bool status_until(const std::function<bool(const nlohmann::json&)>& done, const std::string& token = "") const {
    return poll_until(
        [&] {
          const HttpReply reply = http_request(port, "GET", "/status.json", token);
          if (reply.status != 200 || !reply.error.empty()) return false;
          const auto status = nlohmann::json::parse(reply.body, nullptr, false);
          return !status.is_discarded() && done(status);
        },
        20s);
  }
};

// Runs a program, its output into `log`; its exit status (−1: could not run).
int run_program(const std::vector<std::string>& argv, const std::string& log, std::chrono::seconds timeout = 60s) {
  Process process(argv, log);
  return process.wait(timeout).value_or(-1);
}

// The power wall with a shared secret in `dir`, written to `config_path`, its
// status server on `status_listen`; its status token (empty: it failed).
std::string wall_with_secret(const std::string& dir, const std::string& config_path, const std::string& status_listen) {
  std::ofstream(dir + "/secret") << "correct horse battery staple\n";
  EXPECT_EQ(chmod((dir + "/secret").c_str(), 0600), 0);
  std::ifstream source(kConfigs + "/powerwall-2x2.json");
  nlohmann::json config = nlohmann::json::parse(source);
  config["master"]["secret_file"] = "secret";
  config["master"]["status"] = {{"listen", status_listen}};
  std::ofstream(config_path) << config.dump(2);
  if (run_program({kMaster, "--config", config_path, "--print-status-token"}, dir + "/token.txt") != 0) {
    ADD_FAILURE() << read_file(dir + "/token.txt");
    return "";
  }
  std::string token = read_file(dir + "/token.txt");
  token.erase(token.find_last_not_of("\n") + 1);
  return token;
}

TEST(OperatorPage, ChromiumSeesEveryNodeUpAndTheFramesAdvance) {
  const std::string config = kConfigs + "/powerwall-2x2.json";
  StatusRun run(config, "100000");
  ASSERT_NE(run.port, 0) << run.master->output();
  ASSERT_TRUE(run.status_until([](const nlohmann::json& s) { return s["nodes_up"] == 4 && s["frame"] > 60; }))
      << run.master->output();
  // The page as a person sees it after a few seconds: filled from the stream.
  HeadlessChromium chromium("http://127.0.0.1:" + std::to_string(run.port) + "/", run.dir);
  ASSERT_TRUE(chromium.error().empty()) << chromium.error();
  const auto text = [&](const std::string& id) {
    return chromium.evaluate("document.getElementById('" + id + "').textContent").value_or("?");
  };
  ASSERT_TRUE(poll_until([&] { return std::atoi(text("updates").c_str()) >= 5; }, 20s))
      << "the page got " << text("updates") << " updates: " << chromium.error();
  const std::string states = chromium
                                 .evaluate(
                                     "Array.from(document.querySelectorAll('tr.node'))"
                                     ".map((r) => r.dataset.id + '=' + r.dataset.state).join(' ')")
                                 .value_or("?");
  EXPECT_EQ(states, "bottom-left=up bottom-right=up top-left=up top-right=up");
  EXPECT_EQ(text("run-state"), "running");
  EXPECT_EQ(text("nodes-up"), "4 / 4");
  const long first = std::atol(text("first-frame").c_str());
  const long frame = std::atol(text("frame").c_str());
  std::cout << "the page: " << text("updates") << " updates, frame " << first << " to " << frame << ", " << text("rate")
            << " Hz\n";
  EXPECT_GT(frame, first + 30) << "the frame counter advances on the page";
  // The screenshot, kept next to the test for a person to look at.
  const std::string shot = std::filesystem::absolute("operator-page.png").string();
  ASSERT_TRUE(chromium.screenshot(shot)) << chromium.error();
  EXPECT_GT(std::filesystem::file_size(shot), 10'000u);
  std::cout << "screenshot: " << shot << "\n";

  // A site's Prometheus reads /metrics: its own checker accepts the text.
  const HttpReply metrics = http_request(run.port, "GET", "/metrics");
  ASSERT_EQ(metrics.status, 200) << metrics.error;
  EXPECT_EQ(metrics.headers.at("content-type"), "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_NE(metrics.body.find("optique_node_up{projector=\"top-left\"} 1\n"), std::string::npos) << metrics.body;
  std::ofstream(run.dir + "/metrics.txt") << metrics.body;
  const int promtool = run_program({"/bin/sh", "-c", "promtool check metrics < '" + run.dir + "/metrics.txt'"},
                                   run.dir + "/promtool.log");
  EXPECT_EQ(promtool, 0) << read_file(run.dir + "/promtool.log");

  run.master->signal(SIGINT);
  EXPECT_EQ(run.master->wait(20s).value_or(-1), 0) << run.master->output();
}

// Beyond loopback, everything but the page needs the token; the token is not
// the secret; controls pause, resume and stop the show.
TEST(OperatorPage, TheTokenGuardsTheDataAndTheControls) {
  const ScratchDir dir_scratch("optique-status-token");
  const std::string dir = dir_scratch.string();
  const std::string config_path = dir + "/wall.json";
  const std::string token = wall_with_secret(dir, config_path, "0.0.0.0");
  ASSERT_EQ(token.size(), 64u) << token;
  EXPECT_EQ(token.find("horse"), std::string::npos);

  StatusRun run(config_path, "100000");
  ASSERT_NE(run.port, 0) << run.master->output();
  EXPECT_EQ(http_request(run.port, "GET", "/status.json").status, 401);
  EXPECT_EQ(http_request(run.port, "GET", "/metrics", std::string(64, '0')).status, 401);
  EXPECT_EQ(http_request(run.port, "GET", "/status.json", "correct horse battery staple").status, 401)
      << "the secret itself is not the token";
  EXPECT_EQ(http_request(run.port, "GET", "/").status, 200) << "the page holds no data";
  ASSERT_TRUE(run.status_until([](const nlohmann::json& s) { return s["nodes_up"] == 4 && s["frame"] > 30; }, token))
      << run.master->output();
  EXPECT_EQ(http_request(run.port, "POST", "/control/pause").status, 401);
  EXPECT_EQ(http_request(run.port, "GET", "/control/pause", token).status, 405);

  // Pause: the frame counter stops; resume: it goes on.
  const HttpReply paused = http_request(run.port, "POST", "/control/pause", token);
  EXPECT_EQ(paused.status, 202) << paused.body;
  ASSERT_TRUE(run.status_until([](const nlohmann::json& s) { return s["state"] == "paused"; }, token));
  const auto frame_paused = run.status(token)["frame"].get<std::uint64_t>();
  std::this_thread::sleep_for(500ms);
  EXPECT_EQ(run.status(token)["frame"].get<std::uint64_t>(), frame_paused) << "no frame while paused";
  EXPECT_EQ(http_request(run.port, "POST", "/control/resume", token).status, 202);
  ASSERT_TRUE(run.status_until([&](const nlohmann::json& s) { return s["frame"] > frame_paused + 30; }, token));

  // Slow and oversized requests are closed; the show goes on.
  RawClient slow(run.port);
  ASSERT_TRUE(slow.send("GET /status.json HTTP/1.1\r\nHost:"));
  RawClient large(run.port);
  ASSERT_TRUE(large.send("GET /status.json HTTP/1.1\r\nHost: x\r\nX-Junk: " + std::string(20000, 'j') + "\r\n\r\n"));
  EXPECT_EQ(parse_reply(large.read_until_closed(5s)).status, 431);
  EXPECT_TRUE(slow.closed_within(10s)) << "a request not whole within 5 s is closed";

  // Stop: the run ends in order, and says who stopped it.
  EXPECT_EQ(http_request(run.port, "POST", "/control/stop", token).status, 202);
  EXPECT_EQ(run.master->wait(20s).value_or(-1), 0) << run.master->output();
  const ClusterRun result = read_cluster_run(run.dir + "/out");
  ASSERT_TRUE(result.error.empty()) << result.error;
  EXPECT_NE(result.report.stopped_because().find("stopped by the operator (127.0.0.1:"), std::string::npos)
      << result.report.stopped_because();
  EXPECT_EQ(result.report.sync().frames_with_missing_node(), 0u);
  const std::string log = run.master->output();
  EXPECT_NE(log.find("paused by the operator"), std::string::npos);
  EXPECT_NE(log.find("resumed by the operator"), std::string::npos);
}

// The live scene on the page, opened with the token: it shows what another
// application placed, and adds, moves, hides and removes instances itself; a
// script on its own WebSocket reads back what the page did.
TEST(OperatorPage, ThePageShowsAndEditsTheLiveScene) {
  const ScratchDir dir_scratch("optique-status-live");
  const std::string dir = dir_scratch.string();
  const std::string config_path = dir + "/wall.json";
  const std::string token = wall_with_secret(dir, config_path, "127.0.0.1");
  ASSERT_EQ(token.size(), 64u);
  std::filesystem::copy_file(std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/torus.glb", dir + "/torus.glb");
  StatusRun run(config_path, "100000", {"--api-port", "0"});
  ASSERT_NE(run.port, 0) << run.master->output();
  WebSocketClient refused(run.port, "/api/session?application=script");
  EXPECT_EQ(refused.upgrade_status(), 401) << "with a secret, the token even on loopback";
  WebSocketClient script(run.port, "/api/session?application=script&token=" + token);
  ASSERT_TRUE(script.open()) << script.error() << run.master->output();
  std::uint64_t next_id = 1;
  const auto ask = [&](nlohmann::json request) {
    request["id"] = next_id++;
    EXPECT_TRUE(script.send(request.dump()));
    const auto text = script.receive(10s);
    return text ? nlohmann::json::parse(*text)["reply"] : nlohmann::json{{"error", script.error()}};
  };
  const auto instance = [&](const std::string& id) {
    const nlohmann::json scene = ask({{"read_scene", nlohmann::json::object()}})["scene"];
    for (const auto& i : scene["instances"]) {
      if (i["instance"] == id) return i;
    }
    return nlohmann::json();
  };
  const nlohmann::json placed = ask(
      {{"transaction",
        {{"edits",
          {{{"create",
             {{"instance", "from-script"}, {"asset", "cubes"}, {"transform", {{"position", {0.25, 1.0, 0.0}}}}}}}}}}}});
  ASSERT_TRUE(placed.contains("applied")) << placed;

  HeadlessChromium chromium("http://127.0.0.1:" + std::to_string(run.port) + "/#token=" + token, run.dir);
  ASSERT_TRUE(chromium.error().empty()) << chromium.error();
  const auto page = [&](const std::string& expression) { return chromium.evaluate(expression).value_or("?"); };
  const auto row = [&](const std::string& id, const std::string& field) {
    return page("(document.querySelector('tr.instance[data-id=\"" + id + "\"]') || {dataset: {}}).dataset." + field +
                " || 'none'");
  };
  ASSERT_TRUE(poll_until([&] { return row("from-script", "position") == "0.25 1 0"; }, 20s))
      << "the page shows the script's instance: " << row("from-script", "position") << " "
      << page("document.getElementById('live-note').textContent");

  // Added on the page, at x = 0.5.
  page(
      "document.getElementById('add-id').value = 'from-page'; document.getElementById('add-x').value = '0.5';"
      "document.getElementById('add').click(); 'clicked'");
  ASSERT_TRUE(poll_until([&] { return !instance("from-page").is_null(); }, 10s))
      << page("document.getElementById('live-note').textContent");
  EXPECT_EQ(instance("from-page")["transform"]["position"], nlohmann::json({0.5, 1.0, 0.0}));
  EXPECT_EQ(instance("from-page")["asset"], "cubes");
  ASSERT_TRUE(poll_until([&] { return row("from-page", "position") == "0.5 1 0"; }, 5s));
  EXPECT_NE(page("document.getElementById('live-note').textContent").find("every projector shows it from frame"),
            std::string::npos);

  // Selected, moved to x = -0.5, hidden, removed.
  page("document.querySelector('tr.instance[data-id=\"from-page\"]').click(); 'selected'");
  EXPECT_EQ(page("document.getElementById('selected').textContent"), "from-page");
  page("document.getElementById('move-x').value = '-0.5'; document.getElementById('move').click(); 'moved'");
  ASSERT_TRUE(poll_until([&] { return instance("from-page")["transform"]["position"][0] == -0.5; }, 10s));
  page("document.getElementById('toggle').click(); 'hidden'");
  ASSERT_TRUE(poll_until([&] { return instance("from-page")["hidden"] == true; }, 10s));
  ASSERT_TRUE(poll_until([&] { return row("from-page", "hidden") == "true"; }, 5s));
  EXPECT_TRUE(poll_until([&] { return page("document.getElementById('toggle').textContent") == "Show"; }, 5s));
  const std::string shot = std::filesystem::absolute("operator-page-live.png").string();
  ASSERT_TRUE(chromium.screenshot(shot)) << chromium.error();
  std::cout << "screenshot: " << shot << "\n";
  page("document.getElementById('remove').click(); 'removed'");
  ASSERT_TRUE(poll_until([&] { return instance("from-page").is_null(); }, 10s));

  // An asset loaded from the page: a glTF in the config's folder (the assets
  // folder by default), then one chosen on this computer that is no glTF
  // (refused, naming why). The page lists the loaded one for its next add.
  page("document.getElementById('load-id').value = 'ring'; document.getElementById('load-path').value = 'torus.glb';"
       "document.getElementById('load').click(); 'loading'");
  const auto assets = [&] { return ask({{"read_scene", nlohmann::json::object()}})["scene"]["assets"]; };
  ASSERT_TRUE(poll_until([&] { return assets().dump().find("\"ring\"") != std::string::npos; }, 20s))
      << page("document.getElementById('live-note').textContent");
  EXPECT_TRUE(poll_until(
      [&] { return page("Array.from(document.getElementById('add-asset').options).map((o) => o.value).join()") ==
                   "cubes,ring"; },
      5s));
  EXPECT_TRUE(poll_until(
      [&] { return page("document.getElementById('live-note').textContent").starts_with("loaded: every projector"); },
      5s));
  page("const chosen = new DataTransfer(); chosen.items.add(new File(['glTF not really'], 'fake.glb'));"
       "document.getElementById('load-file').files = chosen.files;"
       "document.getElementById('load-id').value = 'fake'; document.getElementById('load').click(); 'loading'");
  EXPECT_TRUE(poll_until(
      [&] { return page("document.getElementById('live-note').textContent").starts_with("refused: load_asset.glb: "); },
      10s))
      << page("document.getElementById('live-note').textContent");
  EXPECT_TRUE(poll_until([&] { return row("from-page", "id") == "none"; }, 5s));
  EXPECT_FALSE(instance("from-script").is_null()) << "the script's instance stays";
  EXPECT_TRUE(run.master->wait_for_output("application 'operator-page' connected from 127.0.0.1:", 1s));

  run.master->signal(SIGINT);
  EXPECT_EQ(run.master->wait(20s).value_or(-1), 0) << run.master->output();
  const ClusterRun result = read_cluster_run(run.dir + "/out");
  ASSERT_TRUE(result.error.empty()) << result.error;
  for (const auto& node : result.report.nodes()) EXPECT_EQ(node.hash_mismatches(), 0u) << node.id();
}

}  // namespace
}  // namespace optique::testing
