// The lists of lights configs write (common/config/light_list.h): indices and
// ranges, each of the syntax's error messages, and the check against a scene.

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "config/light_list.h"

namespace optique::config {
namespace {

std::vector<std::uint32_t> range(std::uint32_t first, std::uint32_t end) {
  std::vector<std::uint32_t> v(end - first);
  std::iota(v.begin(), v.end(), first);
  return v;
}

// Parsed, and checked against a scene of `light_count` lights.
std::vector<std::uint32_t> parsed(std::string_view text, std::size_t light_count) {
  auto result = parse_light_list(text);
  EXPECT_TRUE(result.ok()) << text << ": " << result.error();
  if (result.ok()) {
    EXPECT_EQ(lights_beyond(result.value(), light_count), std::nullopt) << text;
  }
  EXPECT_TRUE(result.ok()) << text << ": " << result.error();
  return result.ok() ? std::move(result).value() : std::vector<std::uint32_t>{};
}

// Why the text does not parse, or else why it does not fit a scene of
// `light_count` lights.
std::string parse_error(std::string_view text, std::size_t light_count) {
  const auto result = parse_light_list(text);
  if (!result.ok()) return result.error();
  const auto beyond = lights_beyond(result.value(), light_count);
  EXPECT_TRUE(beyond) << text;
  return beyond.value_or("");
}

TEST(LightList, ParsesIndicesAndRanges) {
  EXPECT_EQ(parsed("0-6", 20), range(0, 7));
  EXPECT_EQ(parsed("0, 3, 7-9", 20), (std::vector<std::uint32_t>{0, 3, 7, 8, 9}));
  EXPECT_EQ(parsed(" 9 ,\t2 - 4 ,0", 20), (std::vector<std::uint32_t>{0, 2, 3, 4, 9}));
  EXPECT_EQ(parsed("19", 20), (std::vector<std::uint32_t>{19}));
  EXPECT_EQ(parsed("5-5", 20), (std::vector<std::uint32_t>{5}));
  EXPECT_EQ(parsed("", 20), std::vector<std::uint32_t>{});
  EXPECT_EQ(parsed("  ", 0), std::vector<std::uint32_t>{});
}

TEST(LightList, FormatsRunsAsRanges) {
  const std::vector<std::uint32_t> lights{0, 1, 2, 3, 4, 5, 6, 9};
  EXPECT_EQ(format_light_list(lights), "0-6, 9");
  EXPECT_EQ(format_light_list(std::vector<std::uint32_t>{}), "");
  EXPECT_EQ(format_light_list(std::vector<std::uint32_t>{3}), "3");
  EXPECT_EQ(format_light_list(std::vector<std::uint32_t>{3, 4}), "3-4");
  EXPECT_EQ(format_light_list(std::vector<std::uint32_t>{1, 3, 5, 6, 7, 10, 12, 13}), "1, 3, 5-7, 10, 12-13");
}

TEST(LightList, RoundTrips) {
  const std::vector<std::vector<std::uint32_t>> lists{
      {}, {0}, range(0, 24), {0, 2, 4, 6}, {1, 2, 3, 7, 8, 23}, {5, 6, 7, 8, 9, 10, 11, 19}};
  for (const auto& lights : lists) {
    EXPECT_EQ(parsed(format_light_list(lights), 24), lights) << format_light_list(lights);
  }
  // And text in canonical form comes back as it was.
  for (const std::string text : {"0-6, 9", "1, 3, 5-7", "0-23", "4"}) {
    EXPECT_EQ(format_light_list(parsed(text, 24)), text);
  }
}

TEST(LightList, NamesAnEmptyItem) {
  EXPECT_EQ(parse_error("0,,3", 20), "item 2 of the light list \"0,,3\" is empty: remove the extra comma");
  EXPECT_EQ(parse_error("0-6, ", 20), "item 2 of the light list \"0-6, \" is empty: remove the extra comma");
  EXPECT_EQ(parse_error(",1", 20), "item 1 of the light list \",1\" is empty: remove the extra comma");
}

TEST(LightList, NamesWhatIsNotANumber) {
  const std::string suffix = "\" in the light list is not a light index or range (write 7 or 7-9)";
  EXPECT_EQ(parse_error("0, x", 20), "\"x" + suffix);
  EXPECT_EQ(parse_error("1-2-3", 20), "\"1-2-3" + suffix);
  EXPECT_EQ(parse_error("-3", 20), "\"-3" + suffix);
  EXPECT_EQ(parse_error("4-", 20), "\"4-" + suffix);
  EXPECT_EQ(parse_error("+4", 20), "\"+4" + suffix);
  EXPECT_EQ(parse_error("1.5", 20), "\"1.5" + suffix);
  EXPECT_EQ(parse_error("3 4", 20), "\"3 4" + suffix);
  EXPECT_EQ(parse_error("99999999999999999999999", 20), "\"99999999999999999999999" + suffix);
}

TEST(LightList, NamesAReversedRange) {
  EXPECT_EQ(parse_error("0, 6-2", 20), "the range \"6-2\" is reversed: write \"2-6\"");
}

TEST(LightList, NamesALightTheSceneDoesNotHave) {
  EXPECT_EQ(parse_error("0-3, 24", 20), "light 24 does not exist: the scene has 20 lights (0-19)");
  EXPECT_EQ(parse_error("20", 20), "light 20 does not exist: the scene has 20 lights (0-19)");
  EXPECT_EQ(parse_error("18-24", 20), "lights 20-24 do not exist: the scene has 20 lights (0-19)");
  EXPECT_EQ(parse_error("3, 21, 30", 20), "lights 21, 30 do not exist: the scene has 20 lights (0-19)");
  EXPECT_EQ(parse_error("1", 1), "light 1 does not exist: the scene has 1 light (0)");
  EXPECT_EQ(parse_error("0", 0), "light 0 does not exist: the scene has no lights");
}

TEST(LightList, NamesALightListedTwice) {
  EXPECT_EQ(parse_error("3, 1-4", 20), "light 3 is listed twice");
  EXPECT_EQ(parse_error("0-6, 5-9", 20), "light 5 is listed twice");
  EXPECT_EQ(parse_error("7, 7", 20), "light 7 is listed twice");
}

TEST(LightList, RefusesARangeNoSceneCouldHave) {
  // Expanding 0-4000000000 would take minutes and gigabytes: refused by its size.
  EXPECT_EQ(parse_error("0-4000000000", 20),
            "\"0-4000000000\" in the light list goes beyond light 65535, more than a scene may have");
  EXPECT_EQ(parsed("65535", 65536), (std::vector<std::uint32_t>{65535}));
}

}  // namespace
}  // namespace optique::config
