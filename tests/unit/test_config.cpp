// Installation files: common/config/load.h, parse.h and to_schema.h.

#include <gtest/gtest.h>

#include "config/asset_path.h"

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "config/address.h"
#include "config/load.h"
#include "config/parse.h"
#include "config/to_schema.h"
#include "geometry/homography.h"

namespace optique::config {
namespace {

namespace fs = std::filesystem;

// A small valid installation: two screens, two projectors (one with a region).
// Every test below changes one thing in it by exact text replacement.
const char* const kValid = R"json({
  "name": "unit test",
  "screens": [
    {"id": "front", "origin": [-2.0, 0.0, 0.0], "right": [1, 0, 0], "up": [0, 1, 0], "width": 4.0, "height": 2.0},
    {"id": "floor", "origin": [-2.0, 0.0, 2.0], "right": [1, 0, 0], "up": [0, 0, -1], "width": 4.0, "height": 2.0}
  ],
  "projectors": [
    {"id": "p-front", "width": 640, "height": 320, "screen": "front"},
    {"id": "p-floor", "width": 800, "height": 400, "screen": "floor",
     "region": {"x": 1.0, "y": 0.5, "width": 2.0, "height": 1.0}}
  ],
  "viewer": {"eye": [0.0, 1.6, 2.0]},
  "master": {"port": 7400},
  "scene": {"builtin": "cubes"}
})json";

constexpr const char* kOrigin = "test.json";

// `json` with the single occurrence of `from` replaced by `to`.
std::string replaced(const std::string& json, const std::string& from, const std::string& to) {
  const auto at = json.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not in the JSON";
  EXPECT_EQ(json.find(from, at + 1), std::string::npos) << "test setup: '" << from << "' is not unique";
  if (at == std::string::npos) return json;
  std::string out = json;
  out.replace(at, from.size(), to);
  return out;
}

std::string with(const std::string& from, const std::string& to) { return replaced(kValid, from, to); }

std::string test_dir() { return ::testing::TempDir(); }

Result<Installation> parse(const std::string& json) { return parse_installation(json, kOrigin, test_dir()); }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The result failed, and one line of its message reads "test.json: <path>: ..." and
// mentions every fragment.
void expect_problem(const Result<Installation>& result, const std::string& path,
                    const std::vector<std::string>& fragments) {
  ASSERT_FALSE(result.ok()) << "expected a problem at " << path;
  const std::string prefix = std::string(kOrigin) + ": " + path + ": ";
  for (const std::string& line : lines_of(result.error())) {
    if (line.rfind(prefix, 0) != 0) continue;
    bool all = true;
    for (const auto& f : fragments) all = all && line.find(f) != std::string::npos;
    if (all) return;
  }
  std::string wanted;
  for (const auto& f : fragments) wanted += " '" + f + "'";
  ADD_FAILURE() << "no line starting with '" << prefix << "' and containing" << wanted << " in:\n" << result.error();
}

// --- shipped configs -------------------------------------------------------------

TEST(ShippedConfigs, EveryConfigLoadsAndHasAProjector) {
  const fs::path dir = fs::path(OPTIQUE_SOURCE_DIR) / "configs";
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  std::size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".json") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    auto loaded = load_installation(entry.path().string());
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    const LoadedConfig& c = loaded.value();
    EXPECT_GE(c.installation.projectors.size(), 1u);
    EXPECT_GE(c.installation.screens.size(), 1u);
    EXPECT_EQ(c.path, entry.path().string());
    EXPECT_EQ(fs::path(c.directory), dir);
    ASSERT_EQ(c.sha256.size(), 64u);
    EXPECT_EQ(c.sha256.find_first_not_of("0123456789abcdef"), std::string::npos) << c.sha256;
    // Defaults were applied.
    EXPECT_GT(c.installation.master.frame_rate, 0.0);
    // Every projector's geometry is resolved, and it lights its screen.
    for (const Projector& p : c.installation.projectors) {
      auto geometry = geometry::ProjectorGeometry::make(p.homography, p.width, p.height);
      ASSERT_TRUE(geometry.ok()) << p.id << ": " << geometry.error();
      EXPECT_TRUE(geometry::oblique_projection(geometry.value(), c.installation.screen_of(p).area()).ok()) << p.id;
    }
    // Written back as a schema, it parses to the same installation.
    const auto again = parse_installation(to_schema(c.installation), c.directory, "again");
    ASSERT_TRUE(again.ok()) << again.error();
    EXPECT_EQ(to_schema(again.value()).SerializeAsString(), to_schema(c.installation).SerializeAsString());
  }
  EXPECT_GE(count, 1u) << "no *.json in " << dir;
}

TEST(LoadInstallation, MissingFileNamesThePath) {
  const std::string path = (fs::path(test_dir()) / "no-such-dir" / "missing-config.json").string();
  auto loaded = load_installation(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().find(path), std::string::npos) << loaded.error();
  EXPECT_NE(loaded.error().find("cannot open"), std::string::npos) << loaded.error();
}

TEST(LoadInstallation, ProblemsNameTheFilePath) {
  const fs::path file = fs::path(test_dir()) / "optique-test-config-bad-width.json";
  {
    std::ofstream out(file);
    out << with(R"("width": 640)", R"("width": 0)");
  }
  auto loaded = load_installation(file.string());
  fs::remove(file);
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.error().find(file.string() + ": projectors[0].width: "), std::string::npos) << loaded.error();
}

TEST(LoadInstallation, HashIsOfTheFileBytes) {
  const fs::path file = fs::path(test_dir()) / "optique-test-config-valid.json";
  {
    std::ofstream out(file);
    out << kValid;
  }
  auto first = load_installation(file.string());
  {
    std::ofstream out(file, std::ios::app);
    out << "\n";  // whitespace only: same installation, different bytes
  }
  auto second = load_installation(file.string());
  fs::remove(file);
  ASSERT_TRUE(first.ok()) << first.error();
  ASSERT_TRUE(second.ok()) << second.error();
  EXPECT_NE(first.value().sha256, second.value().sha256);
}

// --- the base case ------------------------------------------------------------------

TEST(ParseInstallation, ValidBaseParses) {
  auto parsed = parse(kValid);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().name, "unit test");
  EXPECT_EQ(parsed.value().projectors.size(), 2u);
  EXPECT_TRUE(validate(to_schema(parsed.value()), test_dir()).empty());
}

// --- one test per kind of problem ------------------------------------------------

// Syntax errors say where: the line of the mistake and a column on it.
void expect_syntax_error_on_line_of(const std::string& text, const std::string& mistake) {
  const auto at = text.find(mistake);
  ASSERT_NE(at, std::string::npos);
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n');
  auto parsed = parse(text);
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.error().rfind(std::string(kOrigin) + ":" + std::to_string(line) + ":", 0), 0u) << parsed.error();
  EXPECT_NE(parsed.error().find("not valid JSON"), std::string::npos) << parsed.error();
}

TEST(ParseInstallation, JsonSyntaxErrorNamesLineAndColumn) {
  expect_syntax_error_on_line_of(with(R"("port": 7400)", R"("port" 7400)"), R"("port" 7400)");  // no colon
}

TEST(ParseInstallation, TrailingCommaIsASyntaxError) {
  expect_syntax_error_on_line_of(with(R"("port": 7400})", R"("port": 7400,})"), R"("port": 7400,})");
}

TEST(ParseInstallation, UnknownFieldListsTheFieldsThere) {
  expect_problem(parse(with(R"("id": "front",)", R"("id": "front", "colour": "red",)")), "screens[0].colour",
                 {"no such field (fields here: id, origin, right, up, width, height"});
}

TEST(ParseInstallation, AMisspelledFieldGetsTheNearestName) {
  expect_problem(parse(with(R"("width": 640)", R"("widht": 640)")), "projectors[0].widht",
                 {"no such field: did you mean 'width'?"});
  expect_problem(parse(with(R"("viewer")", R"("viewr")")), "viewr", {"did you mean 'viewer'?"});
}

// Protobuf's parser stops at the first of these and names C++ types
// ("invalid value -640 for type TYPE_UINT32"): every one is listed, in the
// order of the file, in words.
TEST(ParseInstallation, ValuesOfTheWrongKindAreAllListedWithTheirPaths) {
  std::string text = with(R"("id": "p-front", "width": 640)", R"("id": 5, "width": -640)");
  text = replaced(text, R"("height": 400)", R"("height": 1.5)");
  text = replaced(text, R"("port": 7400)", R"("port": "x", "secret_file": true)");
  text = replaced(text, R"("eye": [0.0, 1.6, 2.0])", R"("eye": 3)");
  const auto parsed = parse(text);
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(lines_of(parsed.error()),
            (std::vector<std::string>{
                "test.json: projectors[0].id: expected text in quotes (got the number 5)",
                "test.json: projectors[0].width: must be 0 or more (got -640)",
                "test.json: projectors[1].height: expected a whole number (got 1.5)",
                "test.json: viewer.eye: expected a list [ … ] (got the number 3)",
                "test.json: master.port: expected a whole number, not text (got \"x\"; write it without quotes)",
                "test.json: master.secret_file: expected text in quotes (got true)",
            }))
      << parsed.error();
  EXPECT_EQ(parsed.error().find("TYPE_"), std::string::npos);
}

TEST(ParseInstallation, AScreenWithoutAnIdIsOneProblemNotTwo) {
  const auto parsed = parse(with(R"("id": "front", )", ""));
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(lines_of(parsed.error()), (std::vector<std::string>{"test.json: screens[0].id: every screen needs an id"}))
      << "no 'unknown screen' for the projector that names it";
}

TEST(LoadInstallation, AMissingFileSaysWhy) {
  const std::string path = test_dir() + "/no-such-config.json";
  const auto loaded = load_installation(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.error(), path + ": cannot open the config file: No such file or directory");
}

TEST(ParseInstallation, DuplicateProjectorId) {
  expect_problem(parse(with(R"("id": "p-floor")", R"("id": "p-front")")), "projectors[1].id",
                 {"duplicate projector id 'p-front'"});
}

TEST(ParseInstallation, DuplicateScreenId) {
  const std::string json =
      replaced(with(R"("id": "floor")", R"("id": "front")"), R"("screen": "floor")", R"("screen": "front")");
  expect_problem(parse(json), "screens[1].id", {"duplicate screen id 'front'"});
}

TEST(ParseInstallation, ProjectorOnUnknownScreenListsKnownScreens) {
  expect_problem(parse(with(R"("screen": "floor")", R"("screen": "ceiling")")), "projectors[1].screen",
                 {"unknown screen 'ceiling'", "front, floor"});
}

TEST(ParseInstallation, ZeroWidth) {
  expect_problem(parse(with(R"("width": 640)", R"("width": 0)")), "projectors[0].width",
                 {"must be 1..16384 pixels", "got 0"});
}

TEST(ParseInstallation, RegionPastTheScreen) {
  // x + width = 3 + 2 = 5 m on a 4 m screen.
  expect_problem(parse(with(R"("x": 1.0)", R"("x": 3.0)")), "projectors[1].region",
                 {"extends past the right edge of screen 'floor'", "5 m > 4 m"});
}

TEST(ParseInstallation, RegionPastTheTop) {
  expect_problem(parse(with(R"("y": 0.5)", R"("y": 1.5)")), "projectors[1].region",
                 {"extends past the top edge of screen 'floor'", "2.5 m > 2 m"});
}

TEST(Validate, ShrunkScreenAfterDefaultsCatchesTheDefaultedRegion) {
  // The defaults gave p-front the whole 4 m x 2 m screen, and to_schema writes it
  // out; shrinking the screen afterwards leaves that region hanging over the top.
  auto parsed = parse(kValid);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  schema::Installation inst = to_schema(parsed.value());
  inst.mutable_screens(0)->set_height(1.0);
  const auto problems = validate(inst, test_dir());
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].path, "projectors[0].region");
  EXPECT_NE(problems[0].message.find("top edge of screen 'front'"), std::string::npos) << problems[0].message;
}

TEST(ParseInstallation, RegionExactlyToTheEdgeIsFine) {
  auto parsed = parse(with(R"("x": 1.0)", R"("x": 2.0)"));  // 2 + 2 = 4 m
  EXPECT_TRUE(parsed.ok()) << parsed.error();
}

TEST(ParseInstallation, NonUnitRightVector) {
  expect_problem(parse(with(R"("origin": [-2.0, 0.0, 0.0], "right": [1, 0, 0])",
                            R"("origin": [-2.0, 0.0, 0.0], "right": [2, 0, 0])")),
                 "screens[0].right", {"must be a unit vector", "length 2"});
}

TEST(ParseInstallation, UpNotPerpendicularToRight) {
  expect_problem(parse(with(R"("up": [0, 1, 0])", R"("up": [0.6, 0.8, 0])")), "screens[0].up",
                 {"must be perpendicular to right", "0.6"});
}

TEST(ParseInstallation, NaNInADoubleField) {
  expect_problem(parse(with(R"("width": 4.0, "height": 2.0},
    {"id": "floor")",
                            R"("width": "NaN", "height": 2.0},
    {"id": "floor")")),
                 "screens[0].width", {"must be a finite number", "nan"});
}

TEST(ParseInstallation, InfinityInAVector) {
  expect_problem(parse(with(R"("origin": [-2.0, 0.0, 0.0])", R"("origin": [-2.0, "Infinity", 0.0])")),
                 "screens[0].origin[1]", {"must be a finite number", "inf"});
}

TEST(ParseInstallation, ViewerWithNeitherEyeNorPath) {
  expect_problem(parse(with(R"("viewer": {"eye": [0.0, 1.6, 2.0]})", R"("viewer": {"eye_separation": 0.06})")),
                 "viewer", {"give the eye position"});
}

TEST(ParseInstallation, ViewerWithBothEyeAndPath) {
  expect_problem(parse(with(R"("viewer": {"eye": [0.0, 1.6, 2.0]})",
                            R"("viewer": {"eye": [0.0, 1.6, 2.0], "path": [{"time": 0, "position": [0, 1, 2]}]})")),
                 "viewer", {"not both"});
}

// A tracker's port is reached by whoever can send to it: by default only this
// machine; listening beyond it, only the tracker's address (`from`) is heard, and
// a config without one is refused, its problem listed with the others.
TEST(ParseInstallation, ATrackerListensOnLoopbackUnlessItsAddressIsGiven) {
  const std::string viewer = R"("viewer": {"eye": [0.0, 1.6, 2.0]})";
  const auto tracked = [&](const std::string& tracking) {
    return parse(
        with(viewer, R"("viewer": {"eye": [0.0, 1.6, 2.0], "tracking": {"source": "dtrack")" + tracking + "}}"));
  };
  const auto by_default = tracked("");
  ASSERT_TRUE(by_default) << by_default.error();
  EXPECT_EQ(by_default.value().viewer.tracking->listen, "127.0.0.1");
  for (const char* loopback : {"127.0.0.1", "::1", "127.0.0.9"}) {
    const auto ok = tracked(std::string(R"(, "listen": ")") + loopback + "\"");
    EXPECT_TRUE(ok) << loopback << ": " << (ok ? "" : ok.error());
  }
  const auto with_from = tracked(R"(, "listen": "0.0.0.0", "from": "10.0.0.20")");
  ASSERT_TRUE(with_from) << with_from.error();
  EXPECT_EQ(with_from.value().viewer.tracking->from, "10.0.0.20");
  for (const char* open : {"0.0.0.0", "10.0.0.5", "::"}) {
    const auto refused = tracked(std::string(R"(, "listen": ")") + open + R"(", "smoothing": 2)");
    expect_problem(refused, "viewer.tracking.from", {"is required when listen is", open, "not loopback"});
    expect_problem(refused, "viewer.tracking.smoothing", {"must be in (0, 1)"});
  }
  // A replay listens nowhere.
  EXPECT_TRUE(parse(with(viewer, R"("viewer": {"eye": [0.0, 1.6, 2.0], "tracking": {"source": "replay", )"
                                 R"("file": "head.csv", "listen": "0.0.0.0"}})")));
}

// Built-in navigation: a flystick's, which needs DTrack to hear it; every bad
// setting named, all at once; left out, none.
TEST(ParseInstallation, AFlystickNavigatesWithDTrackAndEveryBadSettingIsNamed) {
  const std::string viewer = R"("viewer": {"eye": [0.0, 1.6, 2.0]})";
  const auto navigated = [&](const std::string& tracking, const std::string& navigation) {
    return parse(
        with(viewer, R"("viewer": {"eye": [0.0, 1.6, 2.0])" + tracking + R"(, "navigation": )" + navigation + "}"));
  };
  const std::string dtrack = R"(, "tracking": {"source": "dtrack"})";
  const auto flown = navigated(dtrack, R"({"mode": "flystick", "flystick": 2, "reset_button": 0})");
  ASSERT_TRUE(flown) << flown.error();
  ASSERT_TRUE(flown.value().viewer.navigation);
  const Navigation& n = *flown.value().viewer.navigation;
  EXPECT_EQ(n.flystick, 2u);
  EXPECT_EQ(n.reset_button, 0u) << "button 0 is a button";
  EXPECT_EQ(n.speed, defaults::kNavigationSpeed);
  EXPECT_EQ(n.dead_zone, defaults::kNavigationDeadZone);
  EXPECT_EQ(n.up, glm::dvec3(0.0, 1.0, 0.0));

  const auto none = navigated(dtrack, R"({"mode": "none"})");
  ASSERT_TRUE(none) << none.error();
  EXPECT_FALSE(none.value().viewer.navigation);

  expect_problem(navigated("", R"({"mode": "flystick"})"), "viewer.navigation.mode",
                 {"flystick needs viewer.tracking with source dtrack"});
  const auto bad = navigated(dtrack, R"({"mode": "flystick", "speed": -1, "turn_speed": 1000, "dead_zone": 0.95,
                                         "reset_button": 64, "up": [0, 2, 0], "pointer": [1, 0]})");
  expect_problem(bad, "viewer.navigation.speed", {"must be in (0, 100] m/s (got -1)"});
  expect_problem(bad, "viewer.navigation.turn_speed", {"must be in (0, 360] degrees/s"});
  expect_problem(bad, "viewer.navigation.dead_zone", {"must be in [0, 0.9]"});
  expect_problem(bad, "viewer.navigation.reset_button", {"must be below 64"});
  expect_problem(bad, "viewer.navigation.up", {"unit"});
  expect_problem(bad, "viewer.navigation.pointer", {"[x, y, z]"});
  expect_problem(navigated(dtrack, R"({"mode": "walk"})"), "viewer.navigation.mode", {"unknown value 'walk'"});
}

TEST(ParseInstallation, ViewerPathTimesMustIncrease) {
  const std::string path = R"("viewer": {"path": [
      {"time": 0.0, "position": [0, 1.6, 2]},
      {"time": 1.5, "position": [1, 1.6, 2]},
      {"time": 1.5, "position": [0, 1.6, 2]}]})";
  expect_problem(parse(with(R"("viewer": {"eye": [0.0, 1.6, 2.0]})", path)), "viewer.path[2].time",
                 {"times must increase", "1.5 after 1.5"});
}

TEST(ParseInstallation, ViewerPathThatIncreasesIsFine) {
  const std::string path = R"("viewer": {"path": [
      {"time": 0.0, "position": [0, 1.6, 2]},
      {"time": 1.5, "position": [1, 1.6, 2]}]})";
  auto parsed = parse(with(R"("viewer": {"eye": [0.0, 1.6, 2.0]})", path));
  EXPECT_TRUE(parsed.ok()) << parsed.error();
}

TEST(ParseInstallation, UnknownBuiltinSceneListsKnownOnes) {
  expect_problem(parse(with(R"("builtin": "cubes")", R"("builtin": "spheres")")), "scene.builtin",
                 {"unknown scene 'spheres'", "cubes", "many-lights", "depth-stack", "moving-square"});
}

TEST(ParseInstallation, GltfFileMissing) {
  const std::string expected_path = (fs::path(test_dir()) / "models/missing-room.glb").string();
  expect_problem(parse(with(R"("builtin": "cubes")", R"("gltf": "models/missing-room.glb")")), "scene.gltf",
                 {"no such file", expected_path});
}

TEST(ParseInstallation, GltfFilePresentRelativeToConfigDir) {
  const fs::path file = fs::path(test_dir()) / "optique-test-room.glb";
  { std::ofstream(file) << "glTF"; }
  auto parsed = parse(with(R"("builtin": "cubes")", R"("gltf": "optique-test-room.glb")"));
  fs::remove(file);
  EXPECT_TRUE(parsed.ok()) << parsed.error();
}

// A glTF model's placement: every bad field named at once, and what parses
// is written back as it was read.
TEST(ParseInstallation, APlacementIsCheckedFieldByFieldAndWrittenBack) {
  const fs::path file = fs::path(test_dir()) / "optique-test-model.glb";
  { std::ofstream(file) << "glTF"; }
  const auto placed = [](const std::string& placement) {
    return parse(with(R"("builtin": "cubes")", R"("gltf": "optique-test-model.glb", "placement": )" + placement));
  };
  const auto bad = placed(
      R"({"position": [0, 1e7, 0], "rotation": [0, 0, 0, 0], "scale": -2, "fit": {"centre": [0, 1], "size": [1, 0, 2]}})");
  expect_problem(bad, "scene.placement", {"position and scale, or fit, not both"});
  expect_problem(bad, "scene.placement.rotation", {"length 0"});
  expect_problem(bad, "scene.placement.fit.centre", {"[x, y, z]", "2 numbers"});
  expect_problem(bad, "scene.placement.fit.size[1]", {"must be in (0,"});
  const auto far = placed(R"({"position": [0, 1e7, 0], "scale": 1e-9})");
  expect_problem(far, "scene.placement.position", {"from the origin"});
  expect_problem(far, "scene.placement.scale", {"alike on every axis"});
  expect_problem(parse(with(R"("builtin": "cubes")", R"("builtin": "cubes", "placement": {"scale": 2})")),
                 "scene.placement", {"built-in scene"});

  const auto fitted = placed(R"({"rotation": [2, 0, 0, 0], "fit": {"centre": [0, 1, -0.5], "size": [2, 1, 0.5]}})");
  ASSERT_TRUE(fitted.ok()) << fitted.error();
  ASSERT_TRUE(fitted.value().scene.placement && fitted.value().scene.placement->fit);
  EXPECT_EQ(fitted.value().scene.placement->rotation, glm::dquat(1, 0, 0, 0)) << "normalized";
  EXPECT_EQ(fitted.value().scene.placement->fit->size, glm::dvec3(2, 1, 0.5));
  const auto at = placed(R"({"position": [1, 2, 3], "scale": 0.01})");
  ASSERT_TRUE(at.ok()) << at.error();
  EXPECT_EQ(at.value().scene.placement->position, glm::dvec3(1, 2, 3));
  EXPECT_EQ(at.value().scene.placement->scale, 0.01);
  for (const auto* parsed : {&fitted, &at}) {
    const auto again = parse_installation(to_schema(parsed->value()), test_dir(), "again");
    ASSERT_TRUE(again.ok()) << again.error();
    EXPECT_EQ(to_schema(again.value()).SerializeAsString(), to_schema(parsed->value()).SerializeAsString());
  }
  fs::remove(file);
}

TEST(ParseInstallation, FrameRateTooHigh) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "frame_rate": 1500)")), "master.frame_rate",
                 {"must be in (0, 1000]", "1500"});
}

TEST(ParseInstallation, FrameRateNegative) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "frame_rate": -30)")), "master.frame_rate",
                 {"must be in (0, 1000]", "-30"});
}

TEST(ParseInstallation, FrameRateAtTheLimitIsFine) {
  auto parsed = parse(with(R"("port": 7400)", R"("port": 7400, "frame_rate": 1000)"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_DOUBLE_EQ(parsed.value().master.frame_rate, 1000.0);
}

// "640" in quotes is text, though Protobuf's JSON reader would take it: said,
// with the field's path, for whole numbers and decimals alike.
TEST(ParseInstallation, ANumberInQuotesIsSaid) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": "7400")")), "master.port",
                 {"expected a whole number, not text", "\"7400\""});
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "frame_rate": "60")")), "master.frame_rate",
                 {"expected a number, not text", "\"60\""});
}

TEST(ParseInstallation, MinPresentedIsAShare) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "min_presented": 90)")), "master.min_presented",
                 {"share of the frames, 0 to 1", "90"});
  auto parsed = parse(with(R"("port": 7400)", R"("port": 7400, "min_presented": 0.9)"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().master.min_presented, 0.9);
  parsed = parse(with(R"("port": 7400)", R"("port": 7400)"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_FALSE(parsed.value().master.min_presented) << "by default: any frame shown at all";
}

TEST(ParseInstallation, UnknownOutputKind) {
  expect_problem(parse(with(R"("screen": "front"})", R"("screen": "front", "output": {"kind": "hologram"}})")),
                 "projectors[0].output.kind", {"unknown value 'hologram'", "headless, window"});
}

TEST(ParseInstallation, UnknownEye) {
  expect_problem(parse(with(R"("screen": "front"})", R"("screen": "front", "eye": "centre"})")), "projectors[0].eye",
                 {"unknown value 'centre'", "mono, left, right"});
}

TEST(ParseInstallation, BadListenAddress) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "listen": "300.1.2.3")")), "master.listen",
                 {"'300.1.2.3' is not an IPv4 or IPv6 address"});
}

TEST(ParseInstallation, IPv4AndIPv6ListenAddressesAreFine) {
  for (const char* address : {"127.0.0.1", "::1", "0.0.0.0"}) {
    auto parsed = parse(with(R"("port": 7400)", std::string(R"("port": 7400, "listen": ")") + address + "\""));
    EXPECT_TRUE(parsed.ok()) << address << ": " << parsed.error();
  }
}

// master.status: loopback by default, port 7480; an explicit 0 is ephemeral.
TEST(ParseInstallation, StatusServerDefaults) {
  auto parsed = parse(with(R"("port": 7400)", R"("port": 7400, "status": {})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  ASSERT_TRUE(parsed.value().master.status);
  EXPECT_EQ(parsed.value().master.status->listen, "127.0.0.1");
  EXPECT_EQ(parsed.value().master.status->port, 7480u);
  EXPECT_EQ(parsed.value().master.status->max_connections, 256u);
  parsed = parse(with(R"("port": 7400)", R"("port": 7400, "status": {"port": 0, "listen": "::1"})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().master.status->port, 0u);
  EXPECT_FALSE(parse(kValid).value().master.status) << "off unless asked for";
}

// Beyond loopback the status needs the token, and the token the shared secret.
TEST(ParseInstallation, StatusBeyondLoopbackNeedsTheSecret) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "status": {"listen": "0.0.0.0"})")),
                 "master.status.listen", {"'0.0.0.0' is reached from other machines", "master.secret_file"});
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "status": {"listen": "lobby", "port": 70000})")),
                 "master.status.listen", {"'lobby' is not an IPv4 or IPv6 address"});
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "status": {"port": 70000})")), "master.status.port",
                 {"got 70000"});
  for (const char* loopback : {"127.0.0.1", "127.8.9.10", "::1", "::ffff:127.0.0.1"}) {
    EXPECT_TRUE(is_loopback_address(loopback)) << loopback;
  }
  for (const char* beyond : {"0.0.0.0", "10.0.0.7", "::", "::ffff:10.0.0.7", "128.0.0.1", "host"}) {
    EXPECT_FALSE(is_loopback_address(beyond)) << beyond;
  }
}

// master.api: off unless given; loopback, port 7490 and the limits by default;
// beyond loopback only with the shared secret.
TEST(ParseInstallation, TheSceneSessionPort) {
  EXPECT_FALSE(parse(kValid).value().master.api) << "off unless asked for";
  auto parsed = parse(with(R"("port": 7400)", R"("port": 7400, "api": {})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  ASSERT_TRUE(parsed.value().master.api);
  const ApiServer& api = *parsed.value().master.api;
  EXPECT_EQ(api.listen, "127.0.0.1");
  EXPECT_EQ(api.port, 7490u);
  EXPECT_EQ(api.max_sessions, 16u);
  EXPECT_EQ(api.max_edits_per_frame, 100000u);
  EXPECT_EQ(api.max_instances, 100000u);
  EXPECT_EQ(api.assets, resolve_asset(".", test_dir())) << "assets from the config's folder";
  EXPECT_TRUE(std::filesystem::path(api.assets).is_absolute());
  parsed = parse(with(R"("port": 7400)", R"("port": 7400, "api": {"assets": "models/../assets"})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().master.api->assets, resolve_asset("assets", test_dir()));
  parsed = parse(with(R"("port": 7400)", R"("port": 7400, "api": {"port": 0, "max_sessions": 2})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().master.api->port, 0u);
  EXPECT_EQ(parsed.value().master.api->max_sessions, 2u);
  // Written back as it was read (a job, check-config).
  EXPECT_TRUE(validate(to_schema(parsed.value()), test_dir()).empty());
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "api": {"listen": "0.0.0.0"})")), "master.api.listen",
                 {"'0.0.0.0' is reached from other machines", "applications must prove", "master.secret_file"});
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "api": {"port": 70000})")), "master.api.port",
                 {"got 70000"});
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "api": {"max_instances": 20000000})")),
                 "master.api.max_instances", {"at most 10000000"});
}

TEST(ParseInstallation, SeveralProblemsReportedAtOnce) {
  std::string json = with(R"("width": 640)", R"("width": 0)");
  json = replaced(json, R"("builtin": "cubes")", R"("builtin": "nope")");
  json = replaced(json, R"("port": 7400)", R"("port": 7400, "listen": "somewhere")");
  auto parsed = parse(json);
  ASSERT_FALSE(parsed.ok());
  const auto lines = lines_of(parsed.error());
  EXPECT_EQ(lines.size(), 3u) << parsed.error();
  for (const auto& line : lines) EXPECT_EQ(line.rfind(std::string(kOrigin) + ": ", 0), 0u) << line;
  expect_problem(parsed, "projectors[0].width", {"got 0"});
  expect_problem(parsed, "scene.builtin", {"'nope'"});
  expect_problem(parsed, "master.listen", {"'somewhere'"});
}

TEST(Validate, ReturnsEveryProblemWithItsPath) {
  auto parsed = parse(kValid);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  schema::Installation inst = to_schema(parsed.value());
  inst.mutable_projectors(1)->set_height(20000);
  inst.mutable_screens(0)->set_pixels_per_metre(-1.0);
  const auto problems = validate(inst, test_dir());
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].path, "screens[0].pixels_per_metre");
  EXPECT_NE(problems[0].message.find("must be >= 0 (got -1)"), std::string::npos) << problems[0].message;
  EXPECT_EQ(problems[1].path, "projectors[1].height");
  EXPECT_NE(problems[1].message.find("got 20000"), std::string::npos) << problems[1].message;
}

// The rule relates two settings, so it must hold with the default heartbeat too
// (a 400 ms liveness timeout would drop peers between 250 ms heartbeats).
TEST(ParseInstallation, LivenessTimeoutCheckedAgainstDefaultHeartbeat) {
  auto parsed = parse(with(R"("port": 7400)", R"("port": 7400, "liveness_timeout_ms": 400)"));
  if (parsed.ok()) {
    const MasterSettings& m = parsed.value().master;
    EXPECT_GT(m.liveness_timeout, 2 * m.heartbeat) << "accepted liveness_timeout_ms " << m.liveness_timeout.count()
                                                   << " with heartbeat_ms " << m.heartbeat.count();
  } else {
    expect_problem(parsed, "master.liveness_timeout_ms", {"twice heartbeat_ms"});
  }
}

TEST(ParseInstallation, LivenessTimeoutCheckedAgainstExplicitHeartbeat) {
  expect_problem(parse(with(R"("port": 7400)", R"("port": 7400, "heartbeat_ms": 300, "liveness_timeout_ms": 600)")),
                 "master.liveness_timeout_ms", {"twice heartbeat_ms"});
}

// --- defaults -----------------------------------------------------------------------

TEST(Defaults, FillFrameRateAndWholeScreenRegion) {
  auto parsed = parse(kValid);
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const Installation& inst = parsed.value();
  EXPECT_DOUBLE_EQ(inst.master.frame_rate, 60.0);
  EXPECT_EQ(inst.master.listen, "0.0.0.0");
  EXPECT_EQ(inst.master.port, 7400u);  // given values stay

  // p-front gave no region: the whole of "front" (4 m x 2 m).
  const Projector& front = inst.projectors[0];
  EXPECT_EQ(front.geometry_source, GeometrySource::whole_screen);
  ASSERT_TRUE(front.region);
  EXPECT_DOUBLE_EQ(front.region->min.x, 0.0);
  EXPECT_DOUBLE_EQ(front.region->min.y, 0.0);
  EXPECT_DOUBLE_EQ(front.region->width(), 4.0);
  EXPECT_DOUBLE_EQ(front.region->height(), 2.0);
  EXPECT_EQ(front.eye, Eye::mono);
  EXPECT_EQ(front.output.kind, OutputKind::headless);
  EXPECT_EQ(front.host, "localhost");
  EXPECT_EQ(inst.screen_of(front).id, "front");

  // p-floor gave one: kept.
  const Projector& floor = inst.projectors[1];
  EXPECT_EQ(floor.geometry_source, GeometrySource::region);
  ASSERT_TRUE(floor.region);
  EXPECT_DOUBLE_EQ(floor.region->min.x, 1.0);
  EXPECT_DOUBLE_EQ(floor.region->min.y, 0.5);
  EXPECT_DOUBLE_EQ(floor.region->width(), 2.0);
  EXPECT_DOUBLE_EQ(floor.region->height(), 1.0);
  EXPECT_EQ(inst.screen_of(floor).id, "floor");
}

TEST(Defaults, KeepGivenValuesAndFillTheRest) {
  schema::Installation inst;
  auto& screen = *inst.add_screens();
  screen.set_id("s");
  for (double v : {0.0, 0.0, 0.0}) screen.add_origin(v);
  for (double v : {1.0, 0.0, 0.0}) screen.add_right(v);
  for (double v : {0.0, 1.0, 0.0}) screen.add_up(v);
  screen.set_width(3.0);
  screen.set_height(1.5);
  auto& p = *inst.add_projectors();
  p.set_id("p");
  p.set_screen("s");
  p.set_width(300);
  p.set_height(150);
  p.set_eye("left");
  for (double v : {0.0, 1.0, 2.0}) inst.mutable_viewer()->add_eye(v);
  inst.mutable_scene()->set_builtin("cubes");
  inst.mutable_master()->set_frame_rate(30.0);
  inst.mutable_master()->set_heartbeat_ms(2000);

  auto parsed = parse_installation(inst, test_dir(), "built.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const Installation& out = parsed.value();
  EXPECT_DOUBLE_EQ(out.master.frame_rate, 30.0);
  EXPECT_EQ(out.master.heartbeat.count(), 2000);
  EXPECT_EQ(out.master.liveness_timeout.count(), 6000);  // 3 heartbeats, above the 3000 floor
  EXPECT_EQ(out.master.max_message_bytes, 16u << 20);
  EXPECT_EQ(out.master.straggler_policy, StragglerPolicy::present);
  EXPECT_NEAR(out.viewer.eye_separation, 0.065, 1e-12);
  EXPECT_DOUBLE_EQ(out.screens[0].pixels_per_metre, 200.0);
  EXPECT_EQ(out.projectors[0].eye, Eye::left);
  EXPECT_EQ(out.projectors[0].content.role, ContentRole::full);
  ASSERT_TRUE(out.projectors[0].region);
  EXPECT_DOUBLE_EQ(out.projectors[0].region->width(), 3.0);
  EXPECT_DOUBLE_EQ(out.projectors[0].region->height(), 1.5);
}

// ------------------------------------------------------------- projector geometry

namespace geometry_tests {

// A keystoned front projector and a second one related to it through a camera:
// projector pixels → camera pixels for each.
const char* const kFirstH = "[300, 20, 10,  -5, -290, 600,  0.02, 0.05, 1]";
const char* const kFirstCamera = "[0.9, 0.05, 40,  0.02, 1.1, 30,  0.0001, 0.0002, 1]";
const char* const kSecondCamera = "[1.2, -0.03, -500,  0.01, 1.0, 20,  0.0002, -0.0001, 1]";

std::string two_through_a_camera(const std::string& second_extra = "") {
  return with(R"({"id": "p-front", "width": 640, "height": 320, "screen": "front"})",
              std::string(R"({"id": "p-front", "width": 640, "height": 320, "screen": "front", "homography": )") +
                  kFirstH + R"(, "camera": {"camera": "cam", "homography": )" + kFirstCamera +
                  R"(}}, {"id": "p-front-2", "width": 640, "height": 320, "screen": "front", "camera": {"camera": )" +
                  R"("cam", "homography": )" + kSecondCamera + "}" + second_extra + "}");
}

glm::dmat3 rows(const std::vector<double>& nine) {
  return geometry::homography_from_rows(std::span<const double, 9>(nine.data(), 9));
}

TEST(ProjectorGeometry, ACameraViewRelatesAPartnerToTheScreen) {
  auto parsed = parse(two_through_a_camera());
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const Projector& first = parsed.value().projectors[0];
  const Projector& second = parsed.value().projectors[1];
  ASSERT_EQ(second.id, "p-front-2");
  EXPECT_EQ(second.geometry_source, GeometrySource::camera);
  const glm::dmat3 h1 = first.homography;
  const glm::dmat3 h2 = second.homography;
  const glm::dmat3 a1c = rows({0.9, 0.05, 40, 0.02, 1.1, 30, 0.0001, 0.0002, 1});
  const glm::dmat3 a2c = rows({1.2, -0.03, -500, 0.01, 1.0, 20, 0.0002, -0.0001, 1});
  // A screen point seen by the camera through either projector is the same
  // camera pixel: A2c · H2 ≅ A1c · H1.
  for (const glm::dvec2 s : {glm::dvec2(0.5, 0.5), glm::dvec2(1.5, 1.2), glm::dvec2(1.0, 0.2)}) {
    const glm::dvec2 via_first = geometry::apply(a1c, geometry::apply(h1, s));
    const glm::dvec2 via_second = geometry::apply(a2c, geometry::apply(h2, s));
    EXPECT_NEAR(via_first.x, via_second.x, 1e-9);
    EXPECT_NEAR(via_first.y, via_second.y, 1e-9);
  }
}

TEST(ProjectorGeometry, ACameraViewWithoutAPartnerIsRefused) {
  std::string json = two_through_a_camera();
  json = replaced(json, R"("camera": {"camera": "cam", "homography": [0.9)",
                  R"("camera": {"camera": "other", "homography": [0.9)");
  auto parsed = parse(json);
  ASSERT_FALSE(parsed.ok());
  expect_problem(parsed, "projectors[1].camera", {"camera 'cam'", "no projector"});
}

TEST(ProjectorGeometry, RegionAndHomographyTogetherAreRefused) {
  auto parsed =
      parse(with(R"("screen": "floor",)", R"("screen": "floor", "homography": [1, 0, 0, 0, 1, 0, 0, 0, 1],)"));
  ASSERT_FALSE(parsed.ok());
  expect_problem(parsed, "projectors[1].region", {"takes no region"});
}

TEST(ProjectorGeometry, AHomographyNeedsNineFiniteNumbers) {
  auto parsed = parse(with(R"("screen": "front"})", R"("screen": "front", "homography": [1, 0, 0, 0, 1, 0, 0, 0]})"));
  ASSERT_FALSE(parsed.ok());
  expect_problem(parsed, "projectors[0].homography", {"9 numbers", "got 8"});
}

TEST(ProjectorGeometry, AProjectorThatMissesItsScreenIsRefused) {
  // Pixels land 100 m to the right of the 4 m screen.
  auto parsed = parse(
      with(R"("screen": "front"})", R"("screen": "front", "homography": [100, 0, -10000, 0, -100, 200, 0, 0, 1]})"));
  ASSERT_FALSE(parsed.ok());
  expect_problem(parsed, "projectors[0]", {"misses the screen"});
}

TEST(ProjectorGeometry, AHorizonThroughTheImageIsRefused) {
  // w of H⁻¹ changes sign across the image: some pixels would land at infinity.
  auto parsed =
      parse(with(R"("screen": "front"})", R"("screen": "front", "homography": [100, 0, 0, 0, 100, 0, 0, 1, -1]})"));
  ASSERT_FALSE(parsed.ok());
  expect_problem(parsed, "projectors[0].homography", {"horizon"});
}

TEST(ProjectorGeometry, ACalibrationFileIsReadIntoTheHomography) {
  const std::string file = test_dir() + "/front.calibration.json";
  std::ofstream(file) << R"({"homography": [[160, 0, 0], [0, -160, 320], [0, 0, 1]], "rms_px": 0.1})";
  auto parsed = parse(with(R"("screen": "front"})", R"("screen": "front", "calibration": "front.calibration.json"})"));
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const Projector& p = parsed.value().projectors[0];
  EXPECT_EQ(p.geometry_source, GeometrySource::calibration);
  const auto nine = geometry::homography_rows(p.homography);
  EXPECT_DOUBLE_EQ(nine[0], 160.0);
  EXPECT_DOUBLE_EQ(nine[5], 320.0);

  std::ofstream(file) << R"({"homography": [[160, 0], [0, -160, 320], [0, 0, 1]]})";
  auto broken = parse(with(R"("screen": "front"})", R"("screen": "front", "calibration": "front.calibration.json"})"));
  ASSERT_FALSE(broken.ok());
  expect_problem(broken, "projectors[0].calibration", {"homography[0]", "3 numbers"});

  // p-front is 640×320: a file fitted for another image size is refused, one for
  // its own size is read.
  std::ofstream(file) << R"({"homography": [[160, 0, 0], [0, -160, 320], [0, 0, 1]],
                             "projector": {"width": 1024, "height": 768}})";
  expect_problem(parse(with(R"("screen": "front"})", R"("screen": "front", "calibration": "front.calibration.json"})")),
                 "projectors[0].calibration",
                 {"fitted for a 1024×768 image, but this projector is 640×320", "calibrate it again"});
  std::ofstream(file) << R"({"homography": [[160, 0, 0], [0, -160, 320], [0, 0, 1]],
                             "projector": {"width": 640, "height": 320}})";
  EXPECT_TRUE(
      parse(with(R"("screen": "front"})", R"("screen": "front", "calibration": "front.calibration.json"})")).ok());
}

}  // namespace geometry_tests

}  // namespace
}  // namespace optique::config
