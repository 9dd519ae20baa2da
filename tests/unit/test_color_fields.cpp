// A projector's colour fields in the config: common/config/color_fields.h, as a
// file gives them (parse_installation) and as a welcome carries them (to_schema).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/load.h"
#include "config/parse.h"
#include "config/to_schema.h"

namespace optique::config {
namespace {

// One projector; `fields` is its color_fields object.
std::string installation_with(const std::string& fields, double frame_rate = 120.0) {
  return R"json({
  "screens": [{"id": "front", "origin": [-1, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0], "width": 2, "height": 1}],
  "projectors": [{"id": "dlp", "width": 320, "height": 160, "screen": "front", "color_fields": )json" +
         fields + R"json(}],
  "viewer": {"eye": [0, 0.5, 2]},
  "master": {"frame_rate": )json" +
         std::to_string(frame_rate) + R"json(},
  "scene": {"builtin": "moving-square"}
})json";
}

Result<Installation> parse(const std::string& fields, double frame_rate = 120.0) {
  return parse_installation(installation_with(fields, frame_rate), "test.json", ::testing::TempDir());
}

// Every line of the error that starts with "test.json: <path>: ".
std::vector<std::string> problems_at(const Result<Installation>& result, const std::string& path) {
  std::vector<std::string> found;
  if (result) return found;
  const std::string prefix = "test.json: projectors[0].color_fields" + path + ": ";
  std::size_t from = 0;
  const std::string& text = result.error();
  while (from < text.size()) {
    const std::size_t end = std::min(text.find('\n', from), text.size());
    const std::string line = text.substr(from, end - from);
    if (line.rfind(prefix, 0) == 0) found.push_back(line.substr(prefix.size()));
    from = end + 1;
  }
  return found;
}

// Exactly one problem at `path`, and it says `fragment`.
void expect_one(const Result<Installation>& result, const std::string& path, const std::string& fragment) {
  const auto found = problems_at(result, path);
  ASSERT_EQ(found.size(), 1u) << (result ? "no problem" : result.error());
  EXPECT_NE(found[0].find(fragment), std::string::npos) << found[0];
}

TEST(ColorFields, ThePapersProjectorAsAPreset) {
  const auto parsed = parse(R"({"preset": "dlp-brg-120hz"})");
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_TRUE(c.sequential());
  EXPECT_EQ(c.images, 1);
  EXPECT_EQ(c.method, FieldMethod::per_field);
  ASSERT_EQ(c.fields.size(), 3u);
  // B R G at −0.2, 0, +0.32 of the frame.
  EXPECT_EQ(c.fields[0].channel, Channel::blue);
  EXPECT_DOUBLE_EQ(c.fields[0].offset, -0.2);
  EXPECT_EQ(c.fields[1].channel, Channel::red);
  EXPECT_DOUBLE_EQ(c.fields[1].offset, 0.0);
  EXPECT_EQ(c.fields[2].channel, Channel::green);
  EXPECT_DOUBLE_EQ(c.fields[2].offset, 0.32);
}

TEST(ColorFields, TheStereoProjectorAsMonoHasSixFieldsInTwoImages) {
  const auto parsed = parse(R"({"preset": "dlp-stereo-as-mono"})", 60.0);  // a 2×60 Hz projector
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_EQ(c.images, 2);
  ASSERT_EQ(c.fields.size(), 6u);
  // −5/6 … +5/6 of 1/120 s, i.e. −5/12 … +5/12 of the 60 Hz frame, each a sixth long:
  // together they fill the frame.
  const Channel order[] = {Channel::blue, Channel::red, Channel::green};
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(c.fields[i].channel, order[i % 3]) << i;
    EXPECT_EQ(c.fields[i].image, static_cast<int>(i / 3)) << i;
    EXPECT_NEAR(c.fields[i].offset, (2.0 * static_cast<double>(i) - 5.0) / 12.0, 1e-15) << i;
    EXPECT_NEAR(c.fields[i].duration, 1.0 / 6.0, 1e-15) << i;
  }
  EXPECT_NEAR(c.fields.front().start(), -0.5, 1e-15);
  EXPECT_NEAR(c.fields.back().end(), 0.5, 1e-15);
}

// What a node's log says of its fields: how many, over how many images, how
// each is drawn; nothing for a projector that shows all colours at once.
TEST(ColorFields, DescribedForTheNodesLog) {
  const auto gathered = parse(R"({"preset": "dlp-brg-120hz", "method": "gather", "velocity_threshold": 24})");
  ASSERT_TRUE(gathered) << gathered.error();
  EXPECT_EQ(describe(gathered.value().projectors[0].color_fields),
            "3 colour fields per frame, gathered from one render (8 samples), blurred above 24.0 px per frame");
  const auto stereo = parse(R"({"preset": "dlp-stereo-as-mono"})", 60.0);
  ASSERT_TRUE(stereo) << stereo.error();
  EXPECT_EQ(describe(stereo.value().projectors[0].color_fields),
            "6 colour fields per frame over 2 images, each drawn at its own time");
  EXPECT_EQ(describe(ColorFields{}), "");
}

// Each channel's share of the frame: what a field's light is divided by while
// it is on (optics::Emission::on_fraction), so a still image looks the same
// whatever the fields. Unequal fields; a channel in each of two images.
TEST(ColorFields, EachChannelIsOnForTheSumOfItsFields) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.4, "duration": 0.1},
      {"channel": "green", "offset": -0.2, "duration": 0.25},
      {"channel": "blue", "offset": 0.05, "duration": 0.2}]})");
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_DOUBLE_EQ(c.on_share(Channel::red), 0.1);
  EXPECT_DOUBLE_EQ(c.on_share(Channel::green), 0.25);
  EXPECT_DOUBLE_EQ(c.on_share(Channel::blue), 0.2);
  const auto stereo = parse(R"({"preset": "dlp-stereo-as-mono"})", 60.0);
  ASSERT_TRUE(stereo) << stereo.error();
  for (const Channel channel : {Channel::red, Channel::green, Channel::blue}) {
    EXPECT_NEAR(stereo.value().projectors[0].color_fields.on_share(channel), 1.0 / 3.0, 1e-15)
        << "a sixth in each of the two images";
  }
}

TEST(ColorFields, FieldsGivenOneByOne) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.3, "duration": 0.3},
      {"channel": "green", "offset": 0.0, "duration": 0.3},
      {"channel": "blue", "offset": 0.3, "duration": 0.3}],
    "method": "off", "velocity_threshold": 12})");
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_EQ(c.fields.size(), 3u);
  EXPECT_EQ(c.method, FieldMethod::off);
  EXPECT_FALSE(c.sequential()) << "off: every colour at the display time";
  EXPECT_DOUBLE_EQ(c.velocity_threshold, 12.0);
}

TEST(ColorFields, AnEmptyObjectIsRefused) {
  const auto parsed = parse_installation(installation_with("{}"), "test.json", ::testing::TempDir());
  ASSERT_FALSE(parsed) << "an empty color_fields says nothing: it is refused";
  EXPECT_EQ(problems_at(parsed, "").size(), 1u) << parsed.error();
}

TEST(ColorFields, AChannelTwiceInOneImage) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.3, "duration": 0.2},
      {"channel": "green", "offset": 0.0, "duration": 0.2},
      {"channel": "red", "offset": 0.3, "duration": 0.2}]})");
  expect_one(parsed, ".fields[2].channel", "red twice in image 0 (also projectors[0].color_fields.fields[0])");
  expect_one(parsed, ".fields", "image 0 has no blue field");
}

TEST(ColorFields, AWindowOutsideTheFrame) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.45, "duration": 0.2},
      {"channel": "green", "offset": 0.0, "duration": 0.2},
      {"channel": "blue", "offset": 0.6, "duration": 0.1}]})");
  expect_one(parsed, ".fields[0].offset", "its window [-0.55, -0.35] leaves the frame");
  EXPECT_EQ(problems_at(parsed, ".fields[2].offset").size(), 1u) << parsed.error();
  EXPECT_TRUE(problems_at(parsed, ".fields[1].offset").empty()) << parsed.error();
}

// The window's end, not its centre, must stay in the frame: a field centred
// inside whose end is past it.
TEST(ColorFields, AWindowCentredInsideButEndingPastTheFrame) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.3, "duration": 0.2},
      {"channel": "green", "offset": 0.0, "duration": 0.2},
      {"channel": "blue", "offset": 0.45, "duration": 0.2}]})");
  expect_one(parsed, ".fields[2].offset", "its window [0.35, 0.55] leaves the frame");
}

TEST(ColorFields, DurationsOfMoreThanAFrame) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.3, "duration": 0.4},
      {"channel": "green", "offset": 0.0, "duration": 0.4},
      {"channel": "blue", "offset": 0.3, "duration": 0.4}]})");
  expect_one(parsed, ".fields", "the durations add to 1.2 frame periods: more than one frame");
}

TEST(ColorFields, OverlappingWindows) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "red", "offset": -0.3, "duration": 0.2},
      {"channel": "green", "offset": -0.15, "duration": 0.2},
      {"channel": "blue", "offset": 0.3, "duration": 0.2}]})");
  expect_one(parsed, ".fields[1].offset", "overlaps projectors[0].color_fields.fields[0]'s [-0.4, -0.2]");
}

TEST(ColorFields, WindowsThatTouchDoNotOverlap) {
  // Sixths written with seven decimals, as a person would.
  const auto parsed = parse(R"({"fields": [
      {"channel": "blue", "offset": -0.3333333, "duration": 0.3333333},
      {"channel": "red", "offset": 0.0, "duration": 0.3333333},
      {"channel": "green", "offset": 0.3333333, "duration": 0.3333333}]})");
  EXPECT_TRUE(parsed) << parsed.error();
}

TEST(ColorFields, BadNamesAndNumbersEachHaveTheirMessage) {
  const auto parsed = parse(R"({"fields": [
      {"channel": "yellow", "offset": 0.0, "duration": 0.2},
      {"channel": "green", "image": 2, "offset": 0.0, "duration": 0.2},
      {"channel": "blue", "offset": 0.3, "duration": 0}],
    "method": "gatherish", "velocity_threshold": -1})");
  EXPECT_EQ(problems_at(parsed, ".fields[0].channel").size(), 1u) << parsed.error();
  EXPECT_EQ(problems_at(parsed, ".fields[1].image").size(), 1u) << parsed.error();
  EXPECT_EQ(problems_at(parsed, ".fields[2].duration").size(), 1u) << parsed.error();
  EXPECT_EQ(problems_at(parsed, ".method").size(), 1u) << parsed.error();
  EXPECT_EQ(problems_at(parsed, ".velocity_threshold").size(), 1u) << parsed.error();
}

TEST(ColorFields, GatherAndItsSamples) {
  const auto parsed = parse(R"({"preset": "dlp-brg-120hz", "method": "gather", "gather_samples": 16})");
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_EQ(c.method, FieldMethod::gather);
  EXPECT_TRUE(c.sequential());
  EXPECT_EQ(c.gather_samples, 16);
  const auto by_default = parse(R"({"preset": "dlp-brg-120hz", "method": "gather"})");
  ASSERT_TRUE(by_default) << by_default.error();
  EXPECT_EQ(by_default.value().projectors[0].color_fields.gather_samples, kDefaultGatherSamples);
  for (const char* samples : {"1", "33"}) {
    expect_one(
        parse(std::string(R"({"preset": "dlp-brg-120hz", "method": "gather", "gather_samples": )") + samples + "}"),
        ".gather_samples", "must be 2…32, or 0 for 8 (got " + std::string(samples) + ")");
  }
}

// Each other field built from one render by up-conversion; it builds every
// field at its moment, so a blur threshold is refused by name.
TEST(ColorFields, UpConversionBuildsTheFieldsAndTakesNoThreshold) {
  const auto parsed = parse(R"({"preset": "dlp-brg-120hz", "method": "up-conversion"})");
  ASSERT_TRUE(parsed) << parsed.error();
  const ColorFields& c = parsed.value().projectors[0].color_fields;
  EXPECT_EQ(c.method, FieldMethod::up_conversion);
  EXPECT_TRUE(c.up_converts());
  EXPECT_FALSE(c.needs_velocity()) << "no velocity target or tiles";
  EXPECT_EQ(to_string(c.method), "up-conversion");
  expect_one(parse(R"({"preset": "dlp-brg-120hz", "method": "up-conversion", "velocity_threshold": 24})"),
             ".velocity_threshold", "up-conversion builds every field at its moment: leave it 0 (got 24)");
}

TEST(ColorFields, UnknownPresetListsThePresets) {
  const auto parsed = parse(R"({"preset": "dlp"})");
  expect_one(parsed, ".preset", "(presets are: dlp-brg-120hz, dlp-stereo-as-mono)");
}

TEST(ColorFields, PresetAndFieldsTogether) {
  const auto parsed = parse(R"({"preset": "dlp-brg-120hz", "fields": [{"channel": "red", "duration": 1}]})");
  EXPECT_EQ(problems_at(parsed, "").size(), 1u) << parsed.error();
}

TEST(ColorFields, AWelcomeCarriesTheFieldsAndTheirSettings) {
  const auto parsed =
      parse(R"({"preset": "dlp-stereo-as-mono", "method": "gather", "velocity_threshold": 24, "gather_samples": 4})",
            60.0);
  ASSERT_TRUE(parsed) << parsed.error();
  const auto again = parse_installation(to_schema(parsed.value()), ::testing::TempDir(), "welcome");
  ASSERT_TRUE(again) << again.error();
  EXPECT_EQ(again.value().projectors[0].color_fields, parsed.value().projectors[0].color_fields);
}

}  // namespace
}  // namespace optique::config
