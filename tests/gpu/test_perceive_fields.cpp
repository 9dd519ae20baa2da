// What an eye that follows the square of configs/dlp-120hz.json sees
// (tools/perceive.h: the projector's frames drawn as its node draws them, put on
// the screen, integrated field by field on a moving retina), at 6 px per frame:
// drawn per field against every colour drawn at the display time.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include <spdlog/sinks/null_sink.h>

#include "image/compare.h"
#include "image/texture_decode.h"
#include "master/run/run_config.h"
#include "process.h"
#include "tools/perceive.h"

namespace optique {
namespace {

namespace fs = std::filesystem;

// configs/dlp-120hz.json with its projector and screen raster 1.65× as fine (the
// square then crosses 6 px per frame) and its fields drawn by `method`.
std::string config_with(const std::string& dir, const std::string& method) {
  std::ifstream in(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-120hz.json");
  std::stringstream text;
  text << in.rdbuf();
  std::string json = text.str();
  json = std::regex_replace(json, std::regex(R"("width": 640, "height": 360)"), R"("width": 1056, "height": 594)");
  json = std::regex_replace(json, std::regex(R"("pixels_per_metre": 160)"), R"("pixels_per_metre": 264)");
  json = std::regex_replace(json, std::regex(R"(\{"preset": "dlp-brg-120hz"\})"),
                            R"({"preset": "dlp-brg-120hz", "method": ")" + method + R"("})");
  const std::string path = dir + "/dlp-" + method + ".json";
  std::ofstream(path) << json;
  return path;
}

struct Seen {
  tools::PerceivedScreen screen;
  std::string out;
};

Seen perceive(const std::string& config, const std::string& track, const std::string& out, std::uint64_t frame = 60) {
  auto loaded = master::load_run_config(config, image::decode_texture);
  EXPECT_TRUE(loaded) << (loaded ? "" : loaded.error());
  if (!loaded) return {};
  tools::PerceiveOptions options;
  options.frame = frame;
  EXPECT_TRUE(tools::parse_track(track, options));
  auto logger = std::make_shared<spdlog::logger>("perceive", std::make_shared<spdlog::sinks::null_sink_mt>());
  auto seen = tools::perceive(loaded.value().config, loaded.value().scene, options, out, *logger);
  EXPECT_TRUE(seen) << (seen ? "" : seen.error());
  if (!seen || seen.value().size() != 1) return {};
  return {seen.value().front(), out};
}

// Per field against one moment per frame, and the gather method (one render
// with each pixel's screen velocity, every field gathered from it along the
// motion) against both: one test, so that the three are perceived once.
TEST(PerceiveFields, PerFieldRemovesTheFringesOfOneMomentAndGatherComesClose) {
  const testing::ScratchDir dir_scratch("optique-perceive");
  const std::string dir = dir_scratch.string();
  const Seen fields = perceive(config_with(dir, "per-field"), "square", dir + "/per-field");
  const Seen one_moment = perceive(config_with(dir, "off"), "square", dir + "/off");
  const Seen gathered = perceive(config_with(dir, "gather"), "square", dir + "/gather");
  ASSERT_FALSE(fields.screen.seen.empty());
  ASSERT_FALSE(gathered.screen.seen.empty());
  const double speed = fields.screen.velocity.x / 120.0;
  std::cout << "eye at " << speed << " px/frame; per-field: fringe " << fields.screen.fringe_px << " px, PSNR_Y "
            << fields.screen.psnr_y_db << " dB; all colours at the display time: fringe " << one_moment.screen.fringe_px
            << " px, PSNR_Y " << one_moment.screen.psnr_y_db << " dB\n";
  EXPECT_NEAR(speed, 6.0, 0.05);
  // One moment per frame: the channels land where the eye was when each field
  // showed, B −0.2 and G +0.32 of a frame: about speed × 0.52 apart.
  EXPECT_NEAR(one_moment.screen.fringe_px, speed * 0.52, 0.25 * speed * 0.52);
  EXPECT_LE(fields.screen.fringe_px, 0.5);
  EXPECT_EQ(fields.screen.ideal_fringe_px, 0.0);
  EXPECT_GE(fields.screen.psnr_y_db - one_moment.screen.psnr_y_db, 10.0);
  // What it wrote: the perceived image, the ideal beside it, and the measures.
  for (const std::string file : {"/perceived/front/frame-000060.png", "/perceived/front/frame-000060.exr",
                                 "/perceived/front.ideal/frame-000060.png", "/perceived/frame-000060.json"}) {
    EXPECT_TRUE(fs::exists(fields.out + file)) << file;
  }
  // It says what the numbers are over: the tracked object's neighbourhood.
  std::stringstream report;
  report << std::ifstream(fields.out + "/perceived/frame-000060.json").rdbuf();
  EXPECT_NE(report.str().find(R"("measured_over": "object")"), std::string::npos) << report.str();

  const int* box = fields.screen.box;
  const auto around = [&](const image::FloatImage& image) {
    return image::crop(image, box[0], box[1], box[2] - box[0], box[3] - box[1]);
  };
  const auto against_fields = image::compare(around(gathered.screen.seen), around(fields.screen.seen));
  ASSERT_TRUE(against_fields) << against_fields.error();
  const image::Comparison& c = against_fields.value();
  std::cout << "gather: fringe " << gathered.screen.fringe_px << " px, PSNR_Y " << gathered.screen.psnr_y_db
            << " dB against the ideal; against per-field's perceived image R " << c.psnr_r << " G " << c.psnr_g
            << " B " << c.psnr_b << " dB\n";
  EXPECT_LE(gathered.screen.fringe_px, 1.0);
  EXPECT_GE(gathered.screen.psnr_y_db - one_moment.screen.psnr_y_db, 10.0);
  // Green is drawn at its own moment, as per-field draws it; red and blue are
  // moved there from it, 0.32 and 0.52 of a frame (measured: R 58.9, B 33.1 dB).
  EXPECT_GE(c.psnr_g, 60.0);
  EXPECT_GE(c.psnr_r, 45.0);
  EXPECT_GE(c.psnr_b, 30.0);
}

// Two DLP projectors side by side (configs/dlp-wall-2.json), the square crossing
// their seam at frame 60: each draws its half of every field at the same moments,
// so the eye sees what one projector of the whole wall would show it.
TEST(PerceiveFields, TheSquareCrossesTheSeamOfTwoDlpTilesWithoutABreak) {
  const testing::ScratchDir dir_scratch("optique-perceive");
  const std::string dir = dir_scratch.string();
  const std::string configs = std::string(OPTIQUE_SOURCE_DIR) + "/configs/";
  const Seen tiles = perceive(configs + "dlp-wall-2.json", "square", dir + "/tiles");
  const Seen single = perceive(configs + "dlp-120hz.json", "square", dir + "/single");
  ASSERT_FALSE(tiles.screen.seen.empty());
  ASSERT_EQ(tiles.screen.seen.width, single.screen.seen.width);
  const int* box = single.screen.box;
  ASSERT_LT(box[0], 320);  // the seam is at x = 320 of the 640 px raster: inside the neighbourhood
  ASSERT_GT(box[2], 320);
  const auto around = [&](const image::FloatImage& image) {
    return image::crop(image, box[0], box[1], box[2] - box[0], box[3] - box[1]);
  };
  const auto compared = image::compare(around(tiles.screen.seen), around(single.screen.seen));
  ASSERT_TRUE(compared) << compared.error();
  std::cout << "two tiles against one projector, around the square on the seam: PSNR_Y "
            << compared.value().psnr_y_weighted << " dB; fringe " << tiles.screen.fringe_px << " px\n";
  EXPECT_GE(compared.value().psnr_y_weighted, 35.0);
  EXPECT_LE(tiles.screen.fringe_px, 0.5);
  fs::remove_all(dir);
}

// A 2×60 Hz stereo projector used as mono (configs/dlp-stereo-as-mono.json): six
// fields per 60 Hz frame, B R G of one image and then of the other, shown half a
// frame later. Drawn at one moment, the same frame shows twice: each channel
// lands twice, and the channels apart.
TEST(PerceiveFields, AStereoProjectorUsedAsMonoShowsEachOfItsSixFieldsAtItsMoment) {
  const testing::ScratchDir dir_scratch("optique-perceive");
  const std::string dir = dir_scratch.string();
  std::ifstream in(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-stereo-as-mono.json");
  std::stringstream text;
  text << in.rdbuf();
  const auto with = [&](const std::string& method) {
    const std::string path = dir + "/stereo-" + method + ".json";
    std::ofstream(path) << std::regex_replace(text.str(), std::regex(R"("preset": "dlp-stereo-as-mono")"),
                                              R"("preset": "dlp-stereo-as-mono", "method": ")" + method + '"');
    return path;
  };
  // Frame 30: the square is halfway across (at 60 Hz, frame 60 is its wrap).
  const Seen fields = perceive(with("per-field"), "square", dir + "/per-field", 30);
  const Seen gathered = perceive(with("gather"), "square", dir + "/gather", 30);
  const Seen twice = perceive(with("off"), "square", dir + "/off", 30);
  const double speed = fields.screen.velocity.x / 60.0;
  std::cout << "eye at " << speed << " px/frame; per-field: fringe " << fields.screen.fringe_px << " px, PSNR_Y "
            << fields.screen.psnr_y_db << " dB; gather: " << gathered.screen.fringe_px << " px, "
            << gathered.screen.psnr_y_db << " dB; the same frame twice: " << twice.screen.fringe_px << " px, "
            << twice.screen.psnr_y_db << " dB\n";
  EXPECT_NEAR(speed, 7.3, 0.1);
  // The same frame twice: blue shows at −5/12 and +1/12 of the frame, green at
  // −1/12 and +5/12; the eye sees their middles 4/12 of a frame apart.
  EXPECT_NEAR(twice.screen.fringe_px, speed * 4.0 / 12.0, 0.25 * speed * 4.0 / 12.0);
  EXPECT_LE(fields.screen.fringe_px, 0.5);
  EXPECT_LE(gathered.screen.fringe_px, 1.0);
  EXPECT_GE(fields.screen.psnr_y_db - twice.screen.psnr_y_db, 10.0);
  EXPECT_GE(gathered.screen.psnr_y_db - twice.screen.psnr_y_db, 10.0);
  fs::remove_all(dir);
}

TEST(PerceiveFields, AnUnknownObjectIsNamedWithTheOnesThereAre) {
  auto loaded =
      master::load_run_config(std::string(OPTIQUE_SOURCE_DIR) + "/configs/dlp-120hz.json", image::decode_texture);
  ASSERT_TRUE(loaded) << loaded.error();
  tools::PerceiveOptions options;
  ASSERT_TRUE(tools::parse_track("ball", options));
  auto logger = std::make_shared<spdlog::logger>("perceive", std::make_shared<spdlog::sinks::null_sink_mt>());
  const auto seen = tools::perceive(loaded.value().config, loaded.value().scene, options, "/nonexistent", *logger);
  ASSERT_FALSE(seen);
  EXPECT_NE(seen.error().find("no object 'ball' (its moving objects: square)"), std::string::npos) << seen.error();
  // Not two numbers: a name with a comma, said to be neither when there is no such object.
  ASSERT_TRUE(tools::parse_track("3,x", options));
  const auto neither = tools::perceive(loaded.value().config, loaded.value().scene, options, "/nonexistent", *logger);
  ASSERT_FALSE(neither);
  EXPECT_NE(neither.error().find("no object '3,x' (its moving objects: square), and it is not vx,vy either"),
            std::string::npos)
      << neither.error();
  EXPECT_TRUE(tools::parse_track("-2.5,1", options));
  ASSERT_TRUE(options.velocity);
  EXPECT_EQ(*options.velocity, glm::dvec2(-2.5, 1.0));
}

}  // namespace
}  // namespace optique
