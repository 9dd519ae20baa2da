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
#include "wall_session.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";
const std::string kWall = std::string(OPTIQUE_SOURCE_DIR) + "/configs/powerwall-2x2.json";
const std::string kTorusGlb = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/torus.glb";
constexpr int kFrames = 360;
constexpr int kCaptureEvery = 60;

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
  auto running = recording_wall(dir, kFrames, kCaptureEvery, {"--node-arg=--cache-dir=" + dir.file("cache")});
  Process& master = *running;
  auto session = wall_session(dir.file("api.port"), "assets", master);
  ASSERT_NE(session, nullptr);
  client::Session& app = *session;
  // Every node is in the frames: the assets are offered to them there.

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

  // While the four nodes ready the assets (the cache's copy checked whole and
  // each upload to the GPU are on the frame thread, on 2 cores shared by four
  // GL nodes and the master), a node gave up one frame of 360 in about one
  // run of 30: at most 2 here. Every state still the master's.
  expect_whole_run(master, live_out, kFrames, 2);
  if (HasFatalFailure()) return;
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
  const image::FloatImage tiles = stitched_wall(live_out, compared);
  const double with_it = expect_near_reference(tiles, drawn.value(), 40.0, "optique-assets-gl-failure");
  auto not_it = image::compare(tiles, without.value());
  ASSERT_TRUE(not_it.ok()) << not_it.error();
  const double without_it = std::min({not_it.value().psnr_r, not_it.value().psnr_g, not_it.value().psnr_b});
  std::printf("frame %llu: stitched tiles vs the journal's reference %.1f dB, vs the wall without the torus %.1f dB\n",
              static_cast<unsigned long long>(compared), with_it, without_it);
  EXPECT_LT(without_it, 30.0) << "the torus is not on the wall";

  // Replayed with no application: the nodes get both assets in their
  // welcome, from a cache that has neither, and draw the same.
  const CapturedRun replayed = run_and_capture(kWall, static_cast<int>(compared) + 1, kCaptureEvery,
                                               {"--replay", journal, "--node-arg=--cache-dir=" + dir.file("cache2")});
  expect_same_captures(live_out, replayed.out, {compared});
}

}  // namespace
}  // namespace optique::testing
