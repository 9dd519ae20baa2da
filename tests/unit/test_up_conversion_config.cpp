// A projector's frame-rate up-conversion in the config (config/up_conversion.h):
// defaults, every bad field named with its own message, all at once, and the
// welcome's round trip.

#include "config/up_conversion.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/load.h"
#include "config/parse.h"
#include "config/to_schema.h"

namespace optique::config {
namespace {

// One projector with this `up_conversion` (JSON).
Result<Installation> with(const std::string& up) {
  const std::string json = R"({"screens": [{"id": "front", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0],
    "width": 4, "height": 2.25, "pixels_per_metre": 160}],
    "projectors": [{"id": "wall", "width": 640, "height": 360, "screen": "front",
                    "up_conversion": )" +
                           up + R"(}],
    "viewer": {"eye": [0, 1.2, 2]}, "scene": {"builtin": "moving-square"}})";
  return parse_installation(json, "test.json", ::testing::TempDir());
}

bool says(const Result<Installation>& parsed, const std::string& fragment) {
  return !parsed && parsed.error().find(fragment) != std::string::npos;
}

// What a node's log says of its up-conversion; nothing when every frame is drawn.
TEST(UpConversion, DescribedForTheNodesLog) {
  const auto adaptive = with(R"({"ratio": 4, "mode": "interpolate", "spread": true})");
  ASSERT_TRUE(adaptive) << adaptive.error();
  EXPECT_EQ(describe(adaptive.value().projectors[0].up_conversion),
            "a key frame every 4 frames, the frames between by motion (interpolate, key frames spread); the ratio "
            "adapts to keep 30.0 dB PSNR_Y");
  const auto fixed = with(R"({"ratio": 2, "method": "average", "mode": "interpolate"})");
  ASSERT_TRUE(fixed) << fixed.error();
  EXPECT_EQ(describe(fixed.value().projectors[0].up_conversion),
            "a key frame every 2 frames, the frames between by average (interpolate)");
  EXPECT_EQ(describe(UpConversion{}), "");
}

TEST(UpConversion, DefaultsToMotionExtrapolatedAndAbsentIsOff) {
  const auto parsed = with(R"({"ratio": 4})");
  ASSERT_TRUE(parsed) << parsed.error();
  const UpConversion& up = parsed.value().projectors[0].up_conversion;
  EXPECT_EQ(up.ratio, 4);
  EXPECT_EQ(up.method, UpMethod::motion);
  EXPECT_EQ(up.mode, UpMode::extrapolate);
  EXPECT_EQ(up.min_psnr, kDefaultMinPsnr);
  EXPECT_TRUE(up.adaptive());
  EXPECT_TRUE(up.enabled());
  EXPECT_FALSE(up.spread) << "a key frame drawn at once unless asked";
  EXPECT_EQ(up.frames_ahead(), 0) << "extrapolation needs nothing sent ahead";
  const auto fixed = with(R"({"ratio": 4, "min_psnr": 0})");
  ASSERT_TRUE(fixed) << fixed.error();
  EXPECT_FALSE(fixed.value().projectors[0].up_conversion.adaptive());
  for (const char* off : {R"({})", R"({"ratio": 1})", R"({"ratio": 0, "method": "average", "mode": "interpolate"})"}) {
    const auto none = with(off);
    ASSERT_TRUE(none) << none.error();
    EXPECT_FALSE(none.value().projectors[0].up_conversion.enabled()) << off;
  }
}

TEST(UpConversion, EveryBadFieldIsNamedAtOnce) {
  const auto parsed = with(R"({"ratio": 17, "method": "blend", "mode": "predict", "min_psnr": 5})");
  ASSERT_FALSE(parsed);
  EXPECT_TRUE(says(parsed, "projectors[0].up_conversion.ratio: must be 2…16")) << parsed.error();
  EXPECT_TRUE(says(parsed, "(got 17)")) << parsed.error();
  EXPECT_TRUE(says(parsed, "projectors[0].up_conversion.method: must be motion or average (got 'blend')"))
      << parsed.error();
  EXPECT_TRUE(says(parsed, "projectors[0].up_conversion.mode: must be extrapolate or interpolate (got 'predict')"))
      << parsed.error();
  EXPECT_TRUE(says(parsed, "projectors[0].up_conversion.min_psnr: must be 10…100 dB of PSNR_Y, or 0 for a fixed ratio"))
      << parsed.error();
}

// A DLP projector that up-converts its frames builds every field between key
// frames, in one image a frame or two: its fields' method must say so.
TEST(UpConversion, WithColourFieldsTheFieldsAreBuiltBetweenKeyFrames) {
  const auto fields = [](const std::string& colour_fields) {
    return with(R"({"ratio": 4}, "color_fields": )" + colour_fields);
  };
  // (dlp-stereo-as-mono: its fields are for the 60 Hz these tests run at)
  const auto built = fields(R"({"preset": "dlp-stereo-as-mono", "method": "up-conversion"})");
  ASSERT_TRUE(built) << built.error();
  EXPECT_TRUE(built.value().projectors[0].up_conversion.enabled());
  EXPECT_TRUE(built.value().projectors[0].color_fields.up_converts());
  for (const char* method : {"per-field", "gather"}) {
    const auto refused = fields(std::string(R"({"preset": "dlp-stereo-as-mono", "method": ")") + method + R"("})");
    EXPECT_TRUE(says(refused, std::string("projectors[0].color_fields.method: must be \"up-conversion\" with "
                                          "up_conversion (got \"") +
                                  method + "\")"))
        << refused.error();
  }
  EXPECT_TRUE(fields(R"({"preset": "dlp-brg-120hz", "method": "off"})")) << "every colour at once: nothing to build";
  const auto two_images = fields(R"({"preset": "dlp-stereo-as-mono", "method": "up-conversion"})");
  ASSERT_TRUE(two_images) << two_images.error();  // both images' fields built
  EXPECT_EQ(two_images.value().projectors[0].color_fields.images, 2);
}

TEST(UpConversion, TheAverageNeedsTheKeyFrameAfter) {
  EXPECT_TRUE(says(with(R"({"ratio": 4, "method": "average"})"), "it needs mode interpolate"));
  EXPECT_TRUE(says(with(R"({"ratio": 4, "method": "average", "mode": "extrapolate"})"), "it needs mode interpolate"));
  EXPECT_TRUE(with(R"({"ratio": 4, "method": "average", "mode": "interpolate"})"));
}

// Interpolation needs the next key frame's scene ratio − 1 frames ahead; drawn
// a band a frame, the one after it, 2·ratio − 1 ahead.
TEST(UpConversion, HowFarAheadTheSceneIsSent) {
  const auto at_once = with(R"({"ratio": 4, "mode": "interpolate"})");
  ASSERT_TRUE(at_once) << at_once.error();
  EXPECT_EQ(at_once.value().projectors[0].up_conversion.frames_ahead(), 3);
  const auto spread = with(R"({"ratio": 16, "mode": "interpolate", "spread": true})");
  ASSERT_TRUE(spread) << spread.error();
  EXPECT_TRUE(spread.value().projectors[0].up_conversion.spread);
  EXPECT_EQ(spread.value().projectors[0].up_conversion.frames_ahead(), kMostFramesAhead);
  const auto extrapolated = with(R"({"ratio": 4, "spread": true})");
  ASSERT_TRUE(extrapolated) << extrapolated.error();
  EXPECT_EQ(extrapolated.value().projectors[0].up_conversion.frames_ahead(), 0);
}

TEST(UpConversion, AWelcomeCarriesIt) {
  const auto parsed =
      with(R"({"ratio": 3, "method": "motion", "mode": "interpolate", "min_psnr": 42, "spread": true})");
  const auto average = with(R"({"ratio": 3, "method": "average", "mode": "interpolate", "spread": true})");
  ASSERT_TRUE(average) << average.error();
  const auto average_again = parse_installation(to_schema(average.value()), ::testing::TempDir(), "welcome");
  ASSERT_TRUE(average_again) << average_again.error();
  EXPECT_EQ(average_again.value().projectors[0].up_conversion, average.value().projectors[0].up_conversion);
  ASSERT_TRUE(parsed) << parsed.error();
  EXPECT_EQ(parsed.value().projectors[0].up_conversion.min_psnr, 42.0);
  EXPECT_TRUE(parsed.value().projectors[0].up_conversion.spread);
  const auto again = parse_installation(to_schema(parsed.value()), ::testing::TempDir(), "welcome");
  ASSERT_TRUE(again) << again.error();
  EXPECT_EQ(again.value().projectors[0].up_conversion, parsed.value().projectors[0].up_conversion);
}

}  // namespace
}  // namespace optique::config

namespace optique::config {
namespace {

// What used to pass without a word: min_psnr that method average ignores, and
// interpolation from a head tracked live (it cannot be sent ahead).
TEST(UpConversion, WhatWouldBeIgnoredOrCannotWorkIsSaid) {
  EXPECT_TRUE(says(with(R"({"ratio": 4, "mode": "interpolate", "method": "average", "min_psnr": 30})"),
                   "projectors[0].up_conversion.min_psnr: the adaptive ratio weighs frames that motion builds"));
  EXPECT_TRUE(with(R"({"ratio": 4, "mode": "interpolate", "method": "average"})")) << "without min_psnr: fine";
  const auto tracked = [](const std::string& source, const std::string& mode) {
    const std::string json =
        R"({"screens": [{"id": "front", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0],
        "width": 4, "height": 2.25}],
        "projectors": [{"id": "wall", "width": 640, "height": 360, "screen": "front",
                        "up_conversion": {"ratio": 4, "mode": ")" +
        mode + R"("}}],
        "viewer": {"eye": [0, 1.2, 2], "tracking": {"source": ")" +
        source + R"(", "body": 1)" + (source == "replay" ? R"(, "file": "walk.csv")" : "") +
        R"(}}, "scene": {"builtin": "moving-square"}})";
    return parse_installation(json, "test.json", ::testing::TempDir());
  };
  EXPECT_TRUE(says(tracked("dtrack", "interpolate"),
                   "projectors[0].up_conversion.mode: interpolate draws key frames from the scene ratio − 1 frames "
                   "ahead, but the head is tracked live"));
  const auto extrapolated = tracked("dtrack", "extrapolate");
  EXPECT_TRUE(extrapolated) << extrapolated.error();
}

// A preset's field times are shares of its projector's frame rate.
TEST(UpConversion, APresetAtAnotherFrameRateIsSaid) {
  const auto dlp = [](const std::string& rate) {
    const std::string json =
        R"({"screens": [{"id": "front", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0],
        "width": 4, "height": 2.25}],
        "projectors": [{"id": "dlp", "width": 640, "height": 360, "screen": "front",
                        "color_fields": {"preset": "dlp-brg-120hz"}}],
        "viewer": {"eye": [0, 1.2, 2]}, "master": {"frame_rate": )" +
        rate + R"(}, "scene": {"builtin": "moving-square"}})";
    return parse_installation(json, "test.json", ::testing::TempDir());
  };
  EXPECT_TRUE(says(dlp("60"), "projectors[0].color_fields.preset: 'dlp-brg-120hz' is the field timing of a 120 Hz "
                              "projector, but master.frame_rate is 60 Hz: each field would last 2 times as long"));
  const auto right = dlp("120");
  EXPECT_TRUE(right) << right.error();
}

}  // namespace
}  // namespace optique::config
