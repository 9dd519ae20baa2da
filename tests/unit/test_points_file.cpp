// The calibrate command's input file: what it accepts, and an error for each
// bad input that names the file, the point and the field.

#include <gtest/gtest.h>

#include "calib/points_file.h"

namespace optique::calib {
namespace {

constexpr const char* kHeader = R"({"projector": {"width": 1920, "height": 1080}, "points": [)";

std::string file_with_points(const std::string& points) { return std::string(kHeader) + points + "]}"; }

std::string error_of(const std::string& text) {
  auto parsed = parse_points_file(text, "pts.json");
  return parsed.ok() ? "(parsed)" : parsed.error();
}

TEST(PointsFile, ReadsScreenPoints) {
  auto parsed = parse_points_file(file_with_points(R"({"pixel": [10.5, 20.5], "screen": [0, 0]},
      {"pixel": [1900, 20], "screen": [4, 0.25]})"),
                                  "pts.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  const PointsFile& file = parsed.value();
  EXPECT_EQ(file.projector.width, 1920);
  EXPECT_EQ(file.projector.height, 1080);
  EXPECT_EQ(file.kind, PointKind::kScreen);
  ASSERT_EQ(file.pixels.size(), 2u);
  EXPECT_EQ(file.pixels[0], glm::dvec2(10.5, 20.5));
  EXPECT_EQ(file.screen[1], glm::dvec2(4.0, 0.25));
  EXPECT_TRUE(file.tracker.empty());
  EXPECT_FALSE(file.tracker_to_screen.has_value());
  EXPECT_TRUE(file.warnings.empty());
}

TEST(PointsFile, ReadsTrackerPointsWithAGivenFrame) {
  const std::string text = R"({"projector": {"width": 800, "height": 600},
    "tracker_to_screen": [0, 0, 1, 5,  1, 0, 0, 6,  0, 1, 0, 7,  0, 0, 0, 1],
    "points": [{"pixel": [1, 2], "tracker": [0.1, 0.2, 0.3]}]})";
  auto parsed = parse_points_file(text, "pts.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  EXPECT_EQ(parsed.value().kind, PointKind::kTracker);
  EXPECT_EQ(parsed.value().tracker[0], glm::dvec3(0.1, 0.2, 0.3));
  ASSERT_TRUE(parsed.value().tracker_to_screen.has_value());
  const glm::dmat4& m = *parsed.value().tracker_to_screen;
  // Row-major in the file, column-major in glm: row 0 is [0 0 1 5].
  EXPECT_EQ(m[2][0], 1.0);
  EXPECT_EQ(m[3][0], 5.0);
  EXPECT_EQ(m[0][1], 1.0);
  EXPECT_EQ(m[3][2], 7.0);
}

TEST(PointsFile, PixelOutsideTheImageIsAWarning) {
  auto parsed = parse_points_file(file_with_points(R"({"pixel": [2000, 50], "screen": [0, 0]})"), "pts.json");
  ASSERT_TRUE(parsed.ok()) << parsed.error();
  ASSERT_EQ(parsed.value().warnings.size(), 1u);
  EXPECT_EQ(parsed.value().warnings[0], "points[0].pixel (2000, 50) is outside the 1920×1080 image");
}

TEST(PointsFile, SyntaxErrorsGiveLineAndColumn) {
  const std::string text =
      "{\"projector\": {\"width\": 1920, \"height\": 1080},\n \"points\": [\n  {\"pixel\": [1, x], "
      "\"screen\": [0, 0]}]}";
  const std::string error = error_of(text);
  EXPECT_EQ(error.rfind("pts.json:3:17: not valid JSON: ", 0), 0u) << error;
  EXPECT_EQ(error_of("").rfind("pts.json:1:1: not valid JSON", 0), 0u) << error_of("");
}

TEST(PointsFile, BadFieldsNameThePointAndTheField) {
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1, 2], "screen": [0, 0]},
      {"pixel": [1, 2], "screen": [0, 1]}, {"pixel": [5, 2], "screen": [1, 1]}, {"pixel": [1, 2, 3], "screen": [1, 0]})")),
            "pts.json: points[3].pixel: needs 2 numbers (got an array of 3)");
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1, 2], "screen": [0, "a"]})")),
            "pts.json: points[0].screen[1]: needs a number (got a string)");
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1, 2], "tracker": [0, 1]})")),
            "pts.json: points[0].tracker: needs 3 numbers (got an array of 2)");
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": 4, "screen": [0, 1]})")),
            "pts.json: points[0].pixel: needs 2 numbers (got a number)");
  EXPECT_EQ(error_of(file_with_points(R"({"screen": [0, 1]})")), "pts.json: points[0].pixel: missing");
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1, 2]})")).rfind("pts.json: points[0]: needs exactly one of", 0),
            0u);
  EXPECT_NE(
      error_of(file_with_points(R"({"pixel": [1, 2], "screen": [0, 1], "tracker": [0, 1, 2]})")).find("(it has both)"),
      std::string::npos);
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1, 2], "screne": [0, 1]})")),
            "pts.json: points[0]: unknown field \"screne\" (expected \"pixel\", \"screen\", \"tracker\")");
  EXPECT_EQ(error_of(file_with_points(R"([1, 2])")), "pts.json: points[0]: needs an object (got an array of 2)");
  // JSON has no NaN or ∞, and a literal too large for a double is refused where it is.
  EXPECT_EQ(error_of(file_with_points(R"({"pixel": [1e999, 2], "screen": [0, 1]})")),
            "pts.json:1:70: not valid JSON: number overflow parsing '1e999'");
}

TEST(PointsFile, BadProjectorOrTopLevelIsNamed) {
  EXPECT_EQ(error_of(R"({"points": []})").rfind("pts.json: projector: needs", 0), 0u);
  EXPECT_EQ(error_of(R"({"projector": {"width": 0, "height": 1080}, "points": []})"),
            "pts.json: projector.width: needs a positive whole number of pixels (got 0)");
  EXPECT_EQ(error_of(R"({"projector": {"width": 1920}, "points": []})").rfind("pts.json: projector.height: missing", 0),
            0u);
  EXPECT_EQ(error_of(R"({"projector": {"width": 1920, "height": 1080}})").rfind("pts.json: points: needs an array", 0),
            0u);
  EXPECT_EQ(error_of(R"([])"), "pts.json: needs a JSON object at the top level (got an array of 0)");
  EXPECT_EQ(error_of(R"({"projector": {"width": 1920, "height": 1080}, "points": [], "extra": 1})")
                .rfind("pts.json: top level: unknown field \"extra\"", 0),
            0u);
}

TEST(PointsFile, TrackerToScreenMustBeRigidAndGoWithTrackerPoints) {
  const std::string points = R"("points": [{"pixel": [1, 2], "tracker": [0, 0, 2]}])";
  const std::string header = R"({"projector": {"width": 800, "height": 600}, )";
  EXPECT_NE(
      error_of(header + R"("tracker_to_screen": [2, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1], )" + points + "}")
          .find("pts.json: tracker_to_screen: the rotation is not orthonormal"),
      std::string::npos);
  EXPECT_EQ(error_of(header + R"("tracker_to_screen": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0], )" + points + "}"),
            "pts.json: tracker_to_screen: needs 16 numbers (got an array of 12) (a 4×4 matrix, row-major)");
  EXPECT_EQ(error_of(header + R"("tracker_to_screen": [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0,  0, 0, 0, 1], )" +
                     R"("points": [{"pixel": [1, 2], "screen": [0, 0]}]})")
                .rfind("pts.json: tracker_to_screen: only goes with \"tracker\" points", 0),
            0u);
}

TEST(PointsFile, MissingFileIsNamed) {
  auto parsed = read_points_file("/nonexistent/pts.json");
  ASSERT_FALSE(parsed.ok());
  EXPECT_EQ(parsed.error(), "/nonexistent/pts.json: cannot open the points file: No such file or directory");
}

}  // namespace
}  // namespace optique::calib
