// `optique-master calibrate` as a user runs it: a points file in, a calibration
// file out (read back the way configs read it), and exit status 2 with a
// message naming the problem for input it cannot use.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "config/calibration_file.h"
#include "pinhole_projector.h"
#include "process.h"

namespace optique::testing {
namespace {

using namespace std::chrono_literals;
using nlohmann::json;

const std::string kMaster = std::string(OPTIQUE_BIN_DIR) + "/optique-master";

struct CliRun {
  int status = -1;
  std::string output;  // stdout and stderr
};

CliRun calibrate(const std::string& dir, const std::vector<std::string>& args) {
  std::vector<std::string> argv{kMaster, "calibrate"};
  argv.insert(argv.end(), args.begin(), args.end());
  Process process(argv, dir + "/calibrate.log");
  const auto status = process.wait(30s);
  EXPECT_TRUE(status.has_value()) << "optique-master calibrate did not finish";
  return {status.value_or(-1), process.output()};
}

json points_json(const std::vector<geometry::Correspondence>& points, int width, int height) {
  json doc;
  doc["projector"] = {{"width", width}, {"height", height}};
  doc["points"] = json::array();
  for (const auto& p : points) {
    doc["points"].push_back({{"pixel", {p.pixel.x, p.pixel.y}}, {"screen", {p.screen.x, p.screen.y}}});
  }
  return doc;
}

std::string write(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
  return path;
}

class CalibrateCli : public ::testing::Test {
 protected:
  ScratchDir dir_scratch{"optique-calibrate"};
  const std::string dir = dir_scratch.string();
  PinholeProjector projector = projector_cases()[1];  // strong oblique
  glm::dmat3 truth = projector.homography();
  std::vector<geometry::Correspondence> noisy() const {
    std::mt19937_64 random(17);
    return with_pixel_noise(grid_points(truth, projector.width, projector.height, 5, 4), 0.5, random);
  }
};

TEST_F(CalibrateCli, GoodInputWritesTheCalibrationFile) {
  const auto points = noisy();
  const std::string in = write(dir + "/pts.json", points_json(points, 1920, 1080).dump(1));
  const std::string out = dir + "/calibration.json";
  const CliRun run = calibrate(dir, {"--points", in, "--out", out});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("reprojection error: rms"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("no warnings"), std::string::npos) << run.output;

  const json doc = json::parse(read_file(out));
  ASSERT_EQ(doc["homography"].size(), 3u);
  EXPECT_EQ(doc["homography"][2][2].get<double>(), 1.0);
  EXPECT_EQ(doc["points"].get<int>(), 20);
  EXPECT_GT(doc["rms_px"].get<double>(), 0.3);
  EXPECT_LT(doc["rms_px"].get<double>(), 1.0);
  EXPECT_GE(doc["max_px"].get<double>(), doc["rms_px"].get<double>());
  EXPECT_GT(doc["condition"].get<double>(), 1.0);
  EXPECT_TRUE(doc["warnings"].is_array() && doc["warnings"].empty()) << doc["warnings"].dump();
  EXPECT_EQ(doc["projector"]["width"].get<int>(), 1920);
  EXPECT_EQ(doc["projector"]["height"].get<int>(), 1080);
  EXPECT_EQ(doc["residuals_px"].size(), 20u);
  EXPECT_FALSE(doc.contains("inliers"));
  EXPECT_FALSE(doc.contains("tracker_to_screen"));

  // Read back as a config reads it: close to the true H.
  auto h = config::read_calibration_homography(out, 1920, 1080);
  ASSERT_TRUE(h.ok()) << h.error();
  // On a projector of another size its pixels would land elsewhere: refused.
  const auto other = config::read_calibration_homography(out, 1280, 720);
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.error().find("fitted for a 1920×1080 image, but this projector is 1280×720"), std::string::npos)
      << other.error();
  EXPECT_LT(transfer_error(h.value(), truth, grid_points(truth, 1920, 1080, 5, 4)), 0.5);
}

TEST_F(CalibrateCli, RobustModeNamesTheOutlier) {
  auto points = noisy();
  points[7].pixel += glm::dvec2(40.0, -30.0);
  const std::string in = write(dir + "/pts.json", points_json(points, 1920, 1080).dump());

  const CliRun plain = calibrate(dir, {"--points", in, "--out", dir + "/plain.json"});
  ASSERT_EQ(plain.status, 0) << plain.output;
  EXPECT_NE(plain.output.find("warning: points[7] is "), std::string::npos) << plain.output;
  EXPECT_NE(plain.output.find("--robust"), std::string::npos) << plain.output;

  const CliRun robust = calibrate(dir, {"--points", in, "--out", dir + "/robust.json", "--robust"});
  ASSERT_EQ(robust.status, 0) << robust.output;
  const json doc = json::parse(read_file(dir + "/robust.json"));
  ASSERT_EQ(doc["inliers"].size(), 19u);
  for (const auto& i : doc["inliers"]) EXPECT_NE(i.get<int>(), 7);
  ASSERT_EQ(doc["outliers"].size(), 1u);
  EXPECT_EQ(doc["outliers"][0]["index"].get<int>(), 7);
  EXPECT_GT(doc["outliers"][0]["residual_px"].get<double>(), 40.0);
  EXPECT_LT(doc["rms_px"].get<double>(), 1.0);
}

TEST_F(CalibrateCli, TrackerInputWritesTheScreenFrame) {
  json doc;
  doc["projector"] = {{"width", 1920}, {"height", 1080}};
  doc["points"] = json::array();
  // The wall 2 m in front of the tracker, tilted: tracker = (X, 0.3·Y, 2 + 0.95·Y)
  // up to scale, for screen (X, Y).
  const double c = std::cos(0.3);
  const double s = std::sin(0.3);
  for (const auto& p : grid_points(truth, 1920, 1080, 5, 4)) {
    doc["points"].push_back(
        {{"pixel", {p.pixel.x, p.pixel.y}}, {"tracker", {p.screen.x, c * p.screen.y, 2.0 + s * p.screen.y}}});
  }
  const std::string in = write(dir + "/tracker.json", doc.dump());
  const CliRun run = calibrate(dir, {"--points", in, "--out", dir + "/tracker-out.json"});
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_NE(run.output.find("tracker: plane rms"), std::string::npos) << run.output;
  const json out = json::parse(read_file(dir + "/tracker-out.json"));
  EXPECT_LT(out["plane_rms_m"].get<double>(), 1e-9);
  EXPECT_LT(out["plane_max_m"].get<double>(), 1e-9);
  ASSERT_EQ(out["tracker_to_screen"].size(), 16u);
  EXPECT_EQ(out["tracker_to_screen"][15].get<double>(), 1.0);
  EXPECT_LT(out["max_px"].get<double>(), 1e-6);
}

TEST_F(CalibrateCli, DegenerateInputExitsTwoNamingTheProblem) {
  const auto points = grid_points(truth, 1920, 1080, 5, 4);
  std::vector<geometry::Correspondence> three_on_a_line{points[0], points[2], points[4], points[12]};
  const std::string in = write(dir + "/line.json", points_json(three_on_a_line, 1920, 1080).dump());
  const std::string out = dir + "/never.json";
  const CliRun run = calibrate(dir, {"--points", in, "--out", out});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(in + ": points[0], points[1] and points[2] lie on one line"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(CalibrateCli, BadInputExitsTwoWithFileLineAndField) {
  const std::string syntax = write(dir + "/syntax.json",
                                   "{\"projector\": {\"width\": 1920, \"height\": 1080},\n \"points\": [\n"
                                   "  {\"pixel\": [1, x], \"screen\": [0, 0]}]}");
  CliRun run = calibrate(dir, {"--points", syntax, "--out", dir + "/out.json"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(syntax + ":3:17: not valid JSON"), std::string::npos) << run.output;

  json doc = points_json(noisy(), 1920, 1080);
  doc["points"][3]["pixel"] = {1.0, 2.0, 3.0};
  const std::string field = write(dir + "/field.json", doc.dump());
  run = calibrate(dir, {"--points", field, "--out", dir + "/out.json"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find(field + ": points[3].pixel: needs 2 numbers"), std::string::npos) << run.output;

  run = calibrate(dir, {"--points", dir + "/missing.json", "--out", dir + "/out.json"});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("missing.json: cannot open"), std::string::npos) << run.output;

  run = calibrate(dir, {"--points", field});
  EXPECT_EQ(run.status, 2) << run.output;
  EXPECT_NE(run.output.find("--out"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out.json"));
}

}  // namespace
}  // namespace optique::testing
