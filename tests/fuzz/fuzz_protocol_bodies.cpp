// The protocol cores under fuzzing: a whole simulated cluster driven by the
// input's choices (run_protocol), and one node fed whatever a master could send
// (run_node). Declared in fuzz_bodies.h.

#include <cmath>
#include <vector>

#include "config/load.h"
#include "fuzz_bodies.h"
#include "master/run/run_config.h"
#include "node/protocol.h"
#include "protocol/welcome.h"
#include "sim_cluster.h"
#include "util/finite.h"
#include "util/overloaded.h"

namespace optique::fuzz {
namespace {

// Loaded once per process: a fuzzer runs millions of inputs.
const master::RunConfig& wall() {
  static const master::RunConfig run = [] {
    auto loaded = master::load_run_config(std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json", {});
    if (!loaded) throw std::runtime_error(loaded.error());
    return std::move(loaded).value();
  }();
  return run;
}

std::vector<std::span<const std::uint8_t>> chunks_of(std::span<const std::uint8_t> input) {
  std::vector<std::span<const std::uint8_t>> chunks;
  const std::string_view text(reinterpret_cast<const char*>(input.data()), input.size());
  std::size_t start = 0;
  while (true) {
    const std::size_t at = text.find(kChunkSeparator, start);
    const std::size_t end = at == std::string_view::npos ? text.size() : at;
    chunks.push_back(input.subspan(start, end - start));
    if (at == std::string_view::npos) break;
    start = at + kChunkSeparator.size();
  }
  return chunks;
}

std::string check_job(const protocol::NodeJob& node) {
  const config::ProjectorJob& job = node.job;
  OPTIQUE_FUZZ_REQUIRE(job.installation.screens.size() == 1);
  OPTIQUE_FUZZ_REQUIRE(job.projector < job.installation.projectors.size());
  const config::Screen& screen = job.screen();
  OPTIQUE_FUZZ_REQUIRE(std::isfinite(screen.width) && screen.width > 0.0);
  OPTIQUE_FUZZ_REQUIRE(std::isfinite(screen.height) && screen.height > 0.0);
  OPTIQUE_FUZZ_REQUIRE(util::finite(screen.origin) && util::finite(screen.right) && util::finite(screen.up));
  for (const config::Projector& p : job.installation.projectors) {
    OPTIQUE_FUZZ_REQUIRE(p.width > 0 && p.height > 0);
    OPTIQUE_FUZZ_REQUIRE(util::finite(p.homography));
    OPTIQUE_FUZZ_REQUIRE(geometry::ProjectorGeometry::make(p.homography, p.width, p.height).ok());
  }
  OPTIQUE_FUZZ_REQUIRE(node.frame_period > 0);
  OPTIQUE_FUZZ_REQUIRE(!job.installation.viewer.path.empty());
  return {};
}

std::string check_frame(const node::FrameInput& frame, std::uint32_t light_count) {
  OPTIQUE_FUZZ_REQUIRE(frame.state != nullptr);
  if (frame.focus) {
    OPTIQUE_FUZZ_REQUIRE(std::isfinite(frame.focus->depth) && frame.focus->depth > 0.0);
    OPTIQUE_FUZZ_REQUIRE(std::isfinite(frame.focus->gaze.x) && std::isfinite(frame.focus->gaze.y));
  }
  if (frame.lights != nullptr) {
    for (std::size_t i = 0; i < frame.lights->lights.size(); ++i) {
      // The scene's lights and those applications may add after them.
      OPTIQUE_FUZZ_REQUIRE(frame.lights->lights[i] < light_count + scene::kMaxAddedLights);
      OPTIQUE_FUZZ_REQUIRE(i == 0 || frame.lights->lights[i - 1] < frame.lights->lights[i]);
    }
  }
  return {};
}

// Carries out a node's actions as its shell would with a renderer that takes no
// time; returns the first broken invariant.
std::string carry_out(node::NodeProtocol& node, node::Actions actions, std::uint32_t& light_count, Outcome& outcome) {
  for (node::Action& action : actions) {
    std::string broken;
    std::visit(
        util::Overloaded{
            [&](node::Configure& a) {
              ++outcome.configured;
              broken = check_job(a.job);
              light_count = a.job.light_count;
              if (broken.empty())
                broken = carry_out(node, node.answer(node::Configured{{}, "fuzz", {}}, 0), light_count, outcome);
            },
            [&](node::Render& a) {
              ++outcome.renders;
              broken = check_frame(a.frame, light_count);
              if (broken.empty()) {
                broken = carry_out(node, node.answer(node::FrameRendered{a.frame.frame_id, 1000, {}}, 0), light_count,
                                   outcome);
              }
            },
            [&](node::Skip& a) { broken = check_frame(a.frame, light_count); },
            [&](node::PresentAt& a) {
              broken = carry_out(node, node.due(node::Due::present, a.deadline), light_count, outcome);
            },
            [&](node::Present&) {
              ++outcome.frames_presented;
              broken = carry_out(node, node.answer(node::ImagePresented{}, 0), light_count, outcome);
            },
            [&](node::Close&) { ++outcome.closes; },
            [&](node::Stop&) { ++outcome.closes; },
            // A scene's files: fetched into a cache that takes everything.
            [&](node::PrepareScene& a) {
              outcome.scene_files = a.manifest;
              broken = carry_out(node, node.answer(node::SceneCopyStarted{protocol::SceneFetch::Present{}}, 0),
                                 light_count, outcome);
            },
            [&](node::StoreSceneChunk& a) {
              if (a.file >= outcome.scene_files.files.size() ||
                  a.offset + a.data.size() > outcome.scene_files.files[a.file].size) {
                broken = "a chunk stored outside its file";
              }
              ++outcome.scene_chunks;
            },
            [&](node::FinishScene&) {
              broken = carry_out(node, node.answer(node::SceneCopyFinished{std::string("fuzz.gltf")}, 0), light_count,
                                 outcome);
            },
            // An asset offered in the frames: its files here, a checked offer, given to the renderer.
            [&](node::ReadyAsset& a) {
              if (a.asset.path.empty() || !scene::is_instance_id(a.asset.asset) || a.asset.files.files.empty()) {
                broken = "an asset readied without its files or its id";
              } else {
                ++outcome.assets_readied;
                broken = carry_out(node, node.answer(node::AssetLoaded{a.asset.asset, {}}, 0), light_count, outcome);
              }
            },
            [](auto&) {},
        },
        action);
    if (!broken.empty()) return broken;
  }
  return {};
}

wire::Welcome good_welcome() {
  return protocol::encode_welcome(wall().config.installation, 0, {}, 4, 16'666'666, nullptr);
}

}  // namespace

Outcome run_protocol(std::span<const std::uint8_t> input) {
  Outcome outcome;
  if (input.size() < 2) return outcome;
  master::RunSettings settings;
  settings.frames = 5 + input[0] % 40;
  // An application's edits (SimCluster::edit), staged to the nodes between rounds.
  master::LiveScene live;
  live.add_asset("torus");
  settings.live = &live;
  testing::SimCluster cluster(wall(), settings, input[1] % 16);
  cluster.start();
  for (std::uint8_t choice : input.subspan(2)) {
    cluster.step(choice);
    if (!cluster.violations().empty() || cluster.master_finished()) break;
  }
  cluster.run_promptly(cluster.now() + 30 * clock::kNanosPerSecond);
  for (std::size_t i = 0; i < cluster.nodes(); ++i) {
    outcome.frames_presented += static_cast<int>(cluster.presented(i).size());
  }
  outcome.finished = cluster.master_finished();
  if (!cluster.violations().empty()) {
    outcome.broken = cluster.violations().front();
  } else if (!outcome.finished) {
    outcome.broken = "the run did not end within 30 s of a prompt network";
  }
  return outcome;
}

Outcome run_node(std::span<const std::uint8_t> input) {
  const QuietProtobuf quiet;
  Outcome outcome;
  const auto chunks = chunks_of(input);
  node::NodeSettings settings;
  settings.master = "fuzz:7400";
  settings.id = "bottom-left";
  node::NodeProtocol node(settings);
  std::uint32_t light_count = 0;
  const auto deliver = [&](const wire::Envelope& message) {
    return carry_out(node, node.message(message, 0), light_count, outcome);
  };
  (void)node.connected(0);
  wire::Envelope challenge;
  challenge.set_protocol_version(net::kProtocolVersion);
  challenge.mutable_challenge();
  if (std::string broken = deliver(challenge); !broken.empty()) return {broken};

  wire::Envelope welcome;
  welcome.set_protocol_version(net::kProtocolVersion);
  if (!welcome.mutable_welcome()->ParseFromArray(chunks[0].data(), static_cast<int>(chunks[0].size()))) {
    *welcome.mutable_welcome() = good_welcome();
  }
  if (std::string broken = deliver(welcome); !broken.empty()) {
    outcome.broken = broken;
    return outcome;
  }
  if (node.stopped()) return outcome;  // a welcome it could not take: refused, as it should be
  // The state follows once the node is set up: at once, or after it fetched the
  // scene's files from the messages that follow.
  bool resynced = false;
  const auto resync_when_configured = [&]() -> std::string {
    if (resynced || outcome.configured == 0) return {};
    resynced = true;
    wire::Envelope resync;
    resync.set_protocol_version(net::kProtocolVersion);
    const scene::SceneState empty;
    resync.mutable_resync()->set_state_hash(scene::state_hash(empty));
    *resync.mutable_resync()->mutable_snapshot() = scene::to_snapshot(empty);
    return deliver(resync);
  };
  if (std::string broken = resync_when_configured(); !broken.empty()) {
    outcome.broken = broken;
    return outcome;
  }
  for (std::size_t i = 1; i < chunks.size() && !node.stopped(); ++i) {
    wire::Envelope message;
    if (!message.ParseFromArray(chunks[i].data(), static_cast<int>(chunks[i].size()))) continue;
    std::string broken = deliver(message);
    if (broken.empty()) broken = resync_when_configured();
    if (!broken.empty()) {
      outcome.broken = broken;
      return outcome;
    }
  }
  return outcome;
}

}  // namespace optique::fuzz
