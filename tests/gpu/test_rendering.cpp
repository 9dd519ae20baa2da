// Real nodes rendering with GL (headless, llvmpipe in CI): captured images must fit
// together as the installation says. Label `gpu`.

#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cluster_run.h"
#include "config/load.h"
#include "config/to_schema.h"
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
const std::string kConfigs = std::string(OPTIQUE_SOURCE_DIR) + "/configs";

// A config written to a scratch folder, which goes with it.
struct WrittenConfig {
  std::unique_ptr<ScratchDir> folder;
  std::string path;
  operator const std::string&() const { return path; }  // NOLINT: used where a config path is
};

// A shipped config with another scene and a fixed eye, written to a temp file.
WrittenConfig variant(const std::string& shipped, const std::function<void(schema::Installation&)>& change) {
  auto loaded = config::load_installation(kConfigs + "/" + shipped);
  EXPECT_TRUE(loaded.ok());
  schema::Installation installation = config::to_schema(loaded.value().installation);
  change(installation);
  std::string json;
  EXPECT_TRUE(google::protobuf::util::MessageToJsonString(installation, &json).ok());
  WrittenConfig written{std::make_unique<ScratchDir>("optique-gl"), {}};
  written.path = written.folder->file(shipped);
  std::ofstream(written.path) << json;
  return written;
}

double largest_difference(const image::FloatImage& a, const image::FloatImage& b) {
  auto comparison = image::compare(a, b);
  EXPECT_TRUE(comparison.ok()) << (comparison.ok() ? "" : comparison.error());
  return comparison.ok() ? comparison.value().max_abs_error : 1.0;
}

// Where the image is lit (above `threshold` in green): runs of rows in one column.
std::vector<std::pair<int, int>> lit_runs_in_column(const image::FloatImage& image, int column,
                                                    float threshold = 0.5f) {
  std::vector<std::pair<int, int>> runs;
  int start = -1;
  for (int y = 0; y <= image.height; ++y) {
    const bool lit = y < image.height && image.at(column, y, 1) > threshold;
    if (lit && start < 0) start = y;
    if (!lit && start >= 0) {
      runs.emplace_back(start, y - 1);
      start = -1;
    }
  }
  return runs;
}

TEST(Rendering, TheFourTilesOfThePowerWallEqualTheSingleWall) {
  const CapturedRun tiles = run_and_capture(kConfigs + "/powerwall-2x2.json", 31, 30);
  const CapturedRun whole = run_and_capture(kConfigs + "/single-wall.json", 31, 30);
  const image::FloatImage reference = capture(whole, "wall", 30);
  ASSERT_EQ(reference.width, 640);
  ASSERT_EQ(reference.height, 360);
  // Screen y is up, image rows go down: the top tiles are the upper half.
  image::FloatImage stitched(640, 360, reference.channels);
  image::paste(stitched, capture(tiles, "top-left", 30), 0, 0);
  image::paste(stitched, capture(tiles, "top-right", 30), 320, 0);
  image::paste(stitched, capture(tiles, "bottom-left", 30), 0, 180);
  image::paste(stitched, capture(tiles, "bottom-right", 30), 320, 180);

  auto comparison = image::compare(stitched, reference);
  ASSERT_TRUE(comparison.ok()) << comparison.error();
  const auto& c = comparison.value();
  const double worst = std::min({c.psnr_r, c.psnr_g, c.psnr_b});
  std::printf("stitched tiles vs single wall: PSNR R/G/B %.1f/%.1f/%.1f dB, max abs error %.4f\n", c.psnr_r, c.psnr_g,
              c.psnr_b, c.max_abs_error);
  if (worst < 40.0) {
    const ScratchDir dir_scratch("optique-gl-failure");
    const std::string dir = dir_scratch.string();
    (void)image::write_exr(dir + "/stitched.exr", stitched);
    (void)image::write_exr(dir + "/reference.exr", reference);
    (void)image::write_exr(dir + "/difference.exr", image::difference(stitched, reference, 10.0f));
    ADD_FAILURE() << "stitched tiles vs single wall: PSNR R/G/B " << c.psnr_r << "/" << c.psnr_g << "/" << c.psnr_b
                  << " dB; images and the difference (×10) in " << dir;
  }
  // Something was drawn: not two black images.
  double lit = 0.0;
  for (float v : reference.pixels) lit += v;
  EXPECT_GT(lit, 100.0);
}

TEST(Rendering, GeometryCrossingACaveCornerLinesUpOnBothWalls) {
  const WrittenConfig config = variant("cave-4wall.json", [](schema::Installation& inst) {
    inst.mutable_scene()->set_builtin("corner-probe");
    inst.mutable_viewer()->clear_path();
    for (double v : {0.1, 1.6, 0.2}) inst.mutable_viewer()->add_eye(v);  // off centre: walls see it differently
  });
  const CapturedRun out = run_and_capture(config, 1, 1);
  const image::FloatImage front = capture(out, "front", 0);
  const image::FloatImage left = capture(out, "left", 0);
  const image::FloatImage right = capture(out, "right", 0);
  ASSERT_FALSE(front.empty());
  // front's left edge meets left's right edge; front's right edge meets right's left edge.
  const struct {
    const image::FloatImage& a;
    int column_a;
    const image::FloatImage& b;
    int column_b;
    const char* corner;
  } corners[] = {{front, 0, left, left.width - 1, "front/left"}, {front, front.width - 1, right, 0, "front/right"}};
  for (const auto& corner : corners) {
    const auto runs_a = lit_runs_in_column(corner.a, corner.column_a);
    const auto runs_b = lit_runs_in_column(corner.b, corner.column_b);
    ASSERT_EQ(runs_a.size(), 2u) << corner.corner << ": both bars cross the corner";
    ASSERT_EQ(runs_b.size(), 2u) << corner.corner;
    for (std::size_t i = 0; i < runs_a.size(); ++i) {
      EXPECT_LE(std::abs(runs_a[i].first - runs_b[i].first), 1) << corner.corner << " bar " << i << " top edge";
      EXPECT_LE(std::abs(runs_a[i].second - runs_b[i].second), 1) << corner.corner << " bar " << i << " bottom edge";
    }
  }
}

// Intensity-weighted centre of the lit pixels, in pixels.
double centroid_x(const image::FloatImage& image) {
  double sum = 0.0;
  double weighted = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const double v = image.at(x, y, 1);
      sum += v;
      weighted += v * (x + 0.5);
    }
  }
  return sum > 0.0 ? weighted / sum : -1.0;
}

TEST(Rendering, LeftAndRightEyesDifferByTheParallaxOfTheDepth) {
  const WrittenConfig config = variant("single-wall.json", [](schema::Installation& inst) {
    inst.mutable_scene()->set_builtin("stereo-probe");  // a square 1 m behind the wall, at eye height
    schema::Projector left = inst.projectors(0);
    left.set_width(2560);  // 640 px/m: pixel edges quantize the measurement less
    left.set_height(1440);
    left.set_id("left-eye");
    left.set_eye("left");
    schema::Projector right = left;
    right.set_id("right-eye");
    right.set_eye("right");
    inst.clear_projectors();
    *inst.add_projectors() = left;
    *inst.add_projectors() = right;
  });
  const CapturedRun out = run_and_capture(config, 1, 1);
  const double left_x = centroid_x(capture(out, "left-eye", 0));
  const double right_x = centroid_x(capture(out, "right-eye", 0));
  ASSERT_GT(left_x, 0.0);
  ASSERT_GT(right_x, 0.0);
  // Eye 2 m in front of the wall, the square 1 m behind it: on the wall the two
  // images are sep · d / (D + d) apart, right eye's to the right (uncrossed).
  // Each centroid is within half a pixel of exact (edges snap to pixels).
  const double separation = 0.065;
  const double pixels_per_metre = 2560.0 / 4.0;
  const double on_wall = separation / 2.0 * (1.0 - 2.0 / 3.0);  // each eye's image from the centre, metres
  EXPECT_NEAR(left_x, (2.0 - on_wall) * pixels_per_metre, 0.5);
  EXPECT_NEAR(right_x, (2.0 + on_wall) * pixels_per_metre, 0.5);
  EXPECT_NEAR(right_x - left_x, separation * 1.0 / (2.0 + 1.0) * pixels_per_metre, 0.5);
}

TEST(Rendering, AWindowOnAProjectorShowsWhatHeadlessRenders) {
  // A window needs a display: a virtual X server stands in for the projector.
  const WrittenConfig windowed = variant("single-wall.json", [](schema::Installation& inst) {
    inst.mutable_projectors(0)->mutable_output()->set_kind("window");
  });
  const ScratchDir dir_scratch("optique-gl");
  const std::string dir = dir_scratch.string();
  Process master({"/usr/bin/xvfb-run", "-a", "-s", "-screen 0 1280x720x24", kMaster, "--config", windowed, "--local",
                  "--frames", "11", "--capture-every", "10", "--out", dir + "/out", "--no-status"},
                 dir + "/master.log");
  ASSERT_EQ(master.wait(120s), 0) << master.output();
  EXPECT_NE(read_file(dir + "/out/logs/wall.log").find(", window"), std::string::npos)
      << read_file(dir + "/out/logs/wall.log");
  const CapturedRun headless = run_and_capture(kConfigs + "/single-wall.json", 11, 10);
  const image::FloatImage sent = capture(dir + "/out", "wall", 10);
  EXPECT_EQ(largest_difference(sent, capture(headless, "wall", 10)), 0.0);
  // What the window itself showed (read back from it before the swap): the same
  // pixels, the right way up, at the projector's size. A black, flipped or
  // scaled window fails here; the captures above come from the framebuffer the
  // window is drawn from, not from the window.
  auto shown = image::read_image(image::frame_path(dir + "/out/nodes/wall/window", 10, "png"));
  ASSERT_TRUE(shown.ok()) << shown.error();
  ASSERT_EQ(shown.value().width, sent.width);
  ASSERT_EQ(shown.value().height, sent.height);
  float brightest = 0.0f;
  for (const float v : sent.pixels) brightest = std::max(brightest, v);
  EXPECT_GT(brightest, 0.5f) << "the frame should show something";
  EXPECT_EQ(largest_difference(shown.value(), sent), 0.0);
}

// A 2×60 Hz stereo projector used as mono (configs/dlp-stereo-as-mono.json): the
// node draws, shows and captures two images per frame, each with its own three
// fields: blue at −5/12 of the frame in the first, +1/12 in the second. On black,
// each channel's centroid is where the square is at its field.
TEST(Rendering, AStereoProjectorUsedAsMonoCapturesBothImagesOfAFrame) {
  const CapturedRun out = run_and_capture(kConfigs + "/dlp-stereo-as-mono.json", 31, 30);
  const image::FloatImage first = capture(out, "dlp", 30);
  auto second = image::read_image(image::frame_path(out.out + "/nodes/dlp/second-image", 30, "png"));
  ASSERT_TRUE(second.ok()) << second.error();
  ASSERT_EQ(second.value().width, first.width);
  ASSERT_EQ(second.value().height, first.height);
  const auto centroid_x = [](const image::FloatImage& image, int channel) {
    double weight = 0.0;
    double sum = 0.0;
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        weight += image.at(x, y, channel);
        sum += image.at(x, y, channel) * (x + 0.5);
      }
    }
    return weight > 0.0 ? sum / weight : -1.0;
  };
  // 3 m/s across 160 px per metre at 60 Hz (the eye is 2 m before the wall, the
  // square 0.2 m behind it): 8 px per frame on the square's plane, 7.27 on the wall.
  const double per_frame = 8.0 * 2.0 / 2.2;
  for (int channel = 0; channel < 3; ++channel) {
    const double moved = centroid_x(second.value(), channel) - centroid_x(first, channel);
    std::cout << "channel " << channel << ": the second image's square " << moved
              << " px on (half a frame: " << 0.5 * per_frame << " px)\n";
    EXPECT_NEAR(moved, 0.5 * per_frame, 0.25) << "channel " << channel;
  }
}

// ------------------------------------------------------------- glTF scenes

const std::string kAnimatedCubes = kConfigs + "/assets/animated-cubes.gltf";

TEST(Rendering, AnAnimatedGltfRendersTheSameOnStackedNodes) {
  const WrittenConfig config = variant("single-wall.json", [](schema::Installation& inst) {
    inst.mutable_scene()->clear_builtin();
    inst.mutable_scene()->set_gltf(kAnimatedCubes);
    schema::Projector a = inst.projectors(0);
    a.set_id("stack-a");
    schema::Projector b = a;
    b.set_id("stack-b");
    inst.clear_projectors();
    *inst.add_projectors() = a;
    *inst.add_projectors() = b;
  });
  const CapturedRun out = run_and_capture(config, 31, 30);
  for (std::uint64_t frame : {0u, 30u}) {
    EXPECT_EQ(largest_difference(capture(out, "stack-a", frame), capture(out, "stack-b", frame)), 0.0)
        << "stacked duplicates differ at frame " << frame;
  }
  EXPECT_GT(largest_difference(capture(out, "stack-a", 0), capture(out, "stack-a", 30)), 0.1)
      << "the animation moved nothing between frames 0 and 30";
  const ClusterRun run = read_cluster_run(out);
  ASSERT_TRUE(run.error.empty()) << run.error;
  ASSERT_EQ(run.report.nodes_size(), 2);
  for (const report::NodeReport& node : run.report.nodes()) {
    EXPECT_EQ(node.hash_mismatches(), 0u) << node.id() << ": the glTF state differs from the master's";
    EXPECT_EQ(node.frames_presented(), 31u) << node.id();
  }
}

WrittenConfig with_gltf(const std::string& gltf) {
  return variant("single-wall.json", [&gltf](schema::Installation& inst) {
    inst.mutable_scene()->clear_builtin();
    inst.mutable_scene()->set_gltf(gltf);
  });
}

TEST(Rendering, BadGltfInputStartsNothingAndSaysWhy) {
  const ScratchDir dir_scratch("optique-gl");
  const std::string dir = dir_scratch.string();
  const std::string malformed = dir + "/malformed.gltf";
  std::ofstream(malformed) << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ ";
  // The shipped asset with a skin added: a feature we cannot draw.
  std::string skinned_text = read_file(kAnimatedCubes);
  const auto brace = skinned_text.rfind('}');
  ASSERT_NE(brace, std::string::npos);
  skinned_text.insert(brace, ", \"skins\": [ { \"joints\": [ 0 ] } ]");
  const std::string skinned = dir + "/skinned.gltf";
  std::ofstream(skinned) << skinned_text;

  // The torus as obj2gltf wrote it (its buffer and texture beside it), spoilt
  // as a user's export might be, each in a folder of its own.
  const std::string torus = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/";
  const auto torus_variant = [&](const std::string& name, const std::string& from, const std::string& to,
                                 std::size_t bin_bytes) {
    const std::string folder = dir + "/" + name;
    std::filesystem::create_directories(folder);
    std::string text = read_file(torus + "torus.gltf");
    if (!from.empty()) {
      const auto at = text.find(from);
      EXPECT_NE(at, std::string::npos) << from;
      if (at != std::string::npos) text.replace(at, from.size(), to);
    }
    std::ofstream(folder + "/torus.gltf") << text;
    std::ofstream(folder + "/torus.bin", std::ios::binary) << read_file(torus + "torus.bin").substr(0, bin_bytes);
    std::filesystem::copy_file(torus + "torus.png", folder + "/torus.png");
    return folder + "/torus.gltf";
  };
  const std::size_t whole = 184352;
  const struct {
    std::string gltf;
    std::string expected;
  } cases[] = {
      {dir + "/missing.gltf", "missing.gltf"},
      {malformed, "malformed.gltf"},
      {skinned, "skin"},
      {torus_variant("escaping", "\"uri\": \"torus.bin\"", "\"uri\": \"../escaping/torus.bin\"", whole),
       "escaping/torus.gltf: buffer 0 '../escaping/torus.bin': its URI leaves the scene's folder"},
      {torus_variant("no-image", "\"uri\": \"torus.png\"", "\"uri\": \"wood.png\"", whole),
       "no-image/torus.gltf: image 0 'wood.png': missing"},
      {torus_variant("truncated", "", "", 1000),
       "truncated/torus.gltf: buffer 0 'torus.bin' is truncated: 1000 bytes where its byteLength says 184352"},
      {torus_variant("meshopt", "\"asset\": {", "\"extensionsRequired\": [\"EXT_meshopt_compression\"], \"asset\": {",
                     whole),
       "meshopt/torus.gltf: requires an extension that optique cannot draw: EXT_meshopt_compression"},
  };
  for (const auto& c : cases) {
    const StandInStart start = start_with_stand_in_nodes(kMaster, with_gltf(c.gltf));
    EXPECT_EQ(start.status, 2) << c.gltf << ":\n" << start.output;
    EXPECT_NE(start.output.find(c.expected), std::string::npos) << start.output;
    EXPECT_FALSE(start.node_started) << c.gltf;
  }
}

}  // namespace
}  // namespace optique::testing
