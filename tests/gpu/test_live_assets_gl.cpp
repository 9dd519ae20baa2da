// Assets an application loads while the frames go on, on real GL nodes of
// the 2×2 power wall: a binary glTF uploaded over the session and a glTF file
// from the master's assets folder reach every node through the scene
// transfer (none of them has a copy), and the reply names a frame from which
// every node draws them. An instance of the uploaded model shows on the
// stitched tiles as the reference render-reference draws from the recorded
// journal; and the journal replayed with no application (the nodes get the
// asset in their welcome then) gives byte-identical captures. Label gpu.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "clients/cpp/session.h"
#include "cluster_run.h"
#include "image/compare.h"
#include "image/frame_files.h"
#include "image/image_io.h"
#include "local_capture.h"
#include "process.h"
#include "scratch.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kWall = std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json";
const std::string kTorusGlb = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/torus.glb";
constexpr int kFrames = 360;
constexpr int kCaptureEvery = 60;

image::FloatImage stitched(const std::string& out, std::uint64_t frame) {
  image::FloatImage wall(640, 360, 4);
  image::paste(wall, capture(out, "top-left", frame), 0, 0);
  image::paste(wall, capture(out, "top-right", frame), 320, 0);
  image::paste(wall, capture(out, "bottom-left", frame), 0, 180);
  image::paste(wall, capture(out, "bottom-right", frame), 320, 180);
  return wall;
}

// "applied", or the refusal's field and reason.
std::string outcome(const Result<client::Outcome>& done) {
  if (!done) return "error: " + done.error();
  return done.value().applied() ? "applied" : done.value().refused->field() + ": " + done.value().refused->reason();
}

TEST(LiveAssetsOnGlNodes, AnUploadedModelIsDrawnByEveryNodeAndTheJournalDrawsIt) {
  ScratchDir dir("optique-assets-gl");
  const std::string journal = dir.file("session.journal");
  const std::string live_out = dir.file("live");
  // A cache of its own for each run: no node has a copy of anything.
  Process master({kMaster, "--config", kWall, "--local", "--frames", std::to_string(kFrames), "--capture-every",
                  std::to_string(kCaptureEvery), "--out", live_out, "--no-status", "--api-port", "0", "--api-port-file",
                  dir.file("api.port"), "--record", journal, "--node-arg=--cache-dir=" + dir.file("cache")},
                 dir.file("live.log"));
  ASSERT_TRUE(wait_for_file(dir.file("api.port"), 30s)) << master.output();
  client::Options options;
  options.port = static_cast<std::uint16_t>(std::stoi(read_file(dir.file("api.port"))));
  options.name = "assets";
  auto session = client::Session::connect(options);
  ASSERT_TRUE(session.ok()) << session.error();
  client::Session& app = *session.value();
  // Once every node is in the frames: the assets are offered to them there.
  session::Subscribe nodes;
  nodes.set_frames(true);
  ASSERT_TRUE(app.subscribe(nodes).ok());
  auto first = app.next_event(60s);
  ASSERT_TRUE(first.ok() && first.value().has_value()) << master.output();

  // Refused, each naming its field: bytes that are no .glb, a path out of
  // the assets folder, a file that is not there.
  EXPECT_EQ(outcome(app.upload_asset("junk", "not a binary gltf at all")),
            "load_asset.glb: is not a binary glTF (.glb): it does not begin with \"glTF\"");
  EXPECT_EQ(outcome(app.load_asset("out", "../CMakeLists.txt")),
            "load_asset.path: must not leave master.api.assets ('..')");
  const std::string missing = outcome(app.load_asset("missing", "assets/no-such.gltf"));
  EXPECT_TRUE(missing.starts_with("load_asset.path: ")) << missing;

  // The torus uploaded, and the same model read from the config's folder.
  const std::string glb = read_file(kTorusGlb);
  ASSERT_FALSE(glb.empty());
  auto uploaded = app.upload_asset("torus", glb);
  ASSERT_EQ(outcome(uploaded), "applied") << master.output();
  auto from_file = app.load_asset("torus-file", "assets/torus/torus.gltf");
  ASSERT_EQ(outcome(from_file), "applied") << master.output();
  EXPECT_EQ(outcome(app.upload_asset("torus", glb)),
            "load_asset.asset: 'torus' is loaded already (an id names one asset for good)");
  auto scene = app.read_scene();
  ASSERT_TRUE(scene.ok()) << scene.error();
  EXPECT_EQ(scene.value().assets_size(), 3) << scene.value().DebugString();

  client::Placement middle{{{0.0, 1.0, 0.3}}, std::nullopt, {{0.6, 0.6, 0.6}}};
  auto created = app.apply(client::Transaction().create("t1", "torus", middle));
  ASSERT_EQ(outcome(created), "applied");
  const std::uint64_t shown_from = created.value().frame;
  std::printf("the upload usable from frame %llu, the file's from %llu, the instance in frame %llu\n",
              static_cast<unsigned long long>(uploaded.value().frame),
              static_cast<unsigned long long>(from_file.value().frame), static_cast<unsigned long long>(shown_from));
  const std::uint64_t compared = (shown_from / kCaptureEvery + 1) * kCaptureEvery;
  ASSERT_LT(compared, static_cast<std::uint64_t>(kFrames)) << "the loads took most of the run: " << master.output();
  app.close();

  ASSERT_EQ(master.wait(300s), 0) << master.output();
  const ClusterRun run = read_cluster_run(live_out);
  ASSERT_EQ(run.error, "");
  ASSERT_EQ(run.report.nodes_size(), 4);
  for (const auto& node : run.report.nodes()) {
    EXPECT_EQ(node.frames_presented(), static_cast<std::uint64_t>(kFrames)) << node.id();
    EXPECT_EQ(node.hash_mismatches(), 0u) << node.id();
  }
  // The four nodes share one cache: one of them fetched each asset while
  // the frames went on, and every one readied it.
  int fetched = 0;
  for (const char* projector : {"top-left", "top-right", "bottom-left", "bottom-right"}) {
    const std::string log = read_file(live_out + "/logs/" + projector + ".log");
    if (log.find("fetched the asset 'torus':") != std::string::npos) ++fetched;
    EXPECT_NE(log.find("the asset 'torus' is ready to draw"), std::string::npos) << projector << ": " << log;
    EXPECT_NE(log.find("the asset 'torus-file' is ready to draw"), std::string::npos) << projector << ": " << log;
  }
  EXPECT_GE(fetched, 1);

  // The reference from the journal against the stitched tiles; and against
  // the wall without the torus, to see that it is there.
  Process reference({kMaster, "render-reference", "--config", kWall, "--frame", std::to_string(compared), "--out",
                     dir.file("reference"), "--replay", journal},
                    dir.file("reference.log"));
  ASSERT_EQ(reference.wait(120s), 0) << reference.output();
  Process bare(
      {kMaster, "render-reference", "--config", kWall, "--frame", std::to_string(compared), "--out", dir.file("bare")},
      dir.file("bare.log"));
  ASSERT_EQ(bare.wait(120s), 0) << bare.output();
  auto drawn = image::read_image(image::frame_path(dir.file("reference") + "/reference/front", compared, "png"));
  auto without = image::read_image(image::frame_path(dir.file("bare") + "/reference/front", compared, "png"));
  ASSERT_TRUE(drawn.ok() && without.ok());
  const image::FloatImage tiles = stitched(live_out, compared);
  auto with_it = image::compare(tiles, drawn.value());
  auto not_it = image::compare(tiles, without.value());
  ASSERT_TRUE(with_it.ok() && not_it.ok());
  const auto worst = [](const image::Comparison& c) { return std::min({c.psnr_r, c.psnr_g, c.psnr_b}); };
  std::printf("frame %llu: stitched tiles vs the journal's reference %.1f dB, vs the wall without the torus %.1f dB\n",
              static_cast<unsigned long long>(compared), worst(with_it.value()), worst(not_it.value()));
  EXPECT_GE(worst(with_it.value()), 40.0);
  EXPECT_LT(worst(not_it.value()), 30.0) << "the torus is not on the wall";
  if (worst(with_it.value()) < 40.0) {
    const ScratchDir kept_scratch("optique-assets-gl-failure");
    (void)image::write_exr(kept_scratch.string() + "/stitched.exr", tiles);
    (void)image::write_exr(kept_scratch.string() + "/reference.exr", drawn.value());
    (void)image::write_exr(kept_scratch.string() + "/difference.exr", image::difference(tiles, drawn.value(), 10.0f));
    ADD_FAILURE() << "images and the difference (×10) in " << kept_scratch.string();
  }

  // Replayed with no application: the nodes get both assets in their
  // welcome, from a cache that has neither, and draw the same.
  const CapturedRun replayed = run_and_capture(kWall, static_cast<int>(compared) + 1, kCaptureEvery,
                                               {"--replay", journal, "--node-arg=--cache-dir=" + dir.file("cache2")});
  for (const char* projector : {"top-left", "top-right", "bottom-left", "bottom-right"}) {
    const std::string a = read_file(image::frame_path(live_out + "/nodes/" + projector, compared, "png"));
    const std::string b = read_file(image::frame_path(replayed.out + "/nodes/" + projector, compared, "png"));
    EXPECT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << projector << " frame " << compared << ": the replay's capture differs";
  }
}

}  // namespace
}  // namespace optique::testing
