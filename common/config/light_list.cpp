#include "config/light_list.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <functional>
#include <set>

namespace optique::config {
namespace {

std::string_view trim(std::string_view text) {
  constexpr std::string_view kSpace = " \t\r\n\f\v";
  const auto first = text.find_first_not_of(kSpace);
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(kSpace);
  return text.substr(first, last - first + 1);
}

// A whole decimal number that fits a light index, digits only (no sign), or nothing.
std::optional<std::uint32_t> parse_index(std::string_view text) {
  if (text.empty() || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  std::uint32_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;  // too large
  return value;
}

// `text` in double quotes. Built by appending: GCC 12 warns falsely (-Wrestrict)
// on "literal" + std::string.
std::string in_quotes(std::string_view text) {
  std::string q;
  q.reserve(text.size() + 2);
  q += '"';
  q += text;
  q += '"';
  return q;
}

std::string scene_lights(std::size_t light_count) {
  if (light_count == 0) return "the scene has no lights";
  if (light_count == 1) return "the scene has 1 light (0)";
  return "the scene has " + std::to_string(light_count) + " lights (0-" + std::to_string(light_count - 1) + ")";
}

}  // namespace

Result<std::vector<std::uint32_t>> parse_light_list(std::string_view text) {
  std::vector<std::uint32_t> lights;
  if (trim(text).empty()) return lights;
  std::set<std::uint32_t> listed;
  std::size_t item_number = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string_view item = trim(text.substr(start, comma - start));
    start = comma + 1;
    ++item_number;
    if (item.empty()) {
      return Error{"item " + std::to_string(item_number) + " of the light list " + in_quotes(text) +
                   " is empty: remove the extra comma"};
    }
    const std::size_t dash = item.find('-');
    const auto low = parse_index(trim(item.substr(0, dash)));
    const auto high = dash == std::string_view::npos ? low : parse_index(trim(item.substr(dash + 1)));
    if (!low || !high) {
      return Error{in_quotes(item) + " in the light list is not a light index or range (write 7 or 7-9)"};
    }
    if (*high >= kMaxLights) {
      return Error{in_quotes(item) + " in the light list goes beyond light " + std::to_string(kMaxLights - 1) +
                   ", more than a scene may have"};
    }
    if (*high < *low) {
      return Error{"the range " + in_quotes(item) + " is reversed: write " +
                   in_quotes(std::to_string(*high) + '-' + std::to_string(*low))};
    }
    for (std::uint64_t light = *low; light <= *high; ++light) {
      if (!listed.insert(static_cast<std::uint32_t>(light)).second) {
        return Error{"light " + std::to_string(light) + " is listed twice"};
      }
      lights.push_back(static_cast<std::uint32_t>(light));
    }
  }
  std::sort(lights.begin(), lights.end());
  return lights;
}

std::optional<std::string> lights_beyond(std::span<const std::uint32_t> lights, std::size_t light_count) {
  const auto first_beyond =
      std::find_if(lights.begin(), lights.end(), [&](std::uint32_t light) { return light >= light_count; });
  if (first_beyond == lights.end()) return std::nullopt;
  const std::vector<std::uint32_t> beyond(first_beyond, lights.end());
  const std::string what = beyond.size() == 1 ? "light " + std::to_string(beyond.front()) + " does not exist"
                                              : "lights " + format_light_list(beyond) + " do not exist";
  return what + ": " + scene_lights(light_count);
}

std::string format_light_list(std::span<const std::uint32_t> lights) {
  assert(std::adjacent_find(lights.begin(), lights.end(), std::greater_equal<>()) == lights.end());
  std::string text;
  for (std::size_t i = 0; i < lights.size();) {
    std::size_t last = i;
    while (last + 1 < lights.size() && lights[last + 1] == lights[last] + 1) ++last;
    if (!text.empty()) text += ", ";
    text += std::to_string(lights[i]);
    if (last > i) {
      text += '-';
      text += std::to_string(lights[last]);
    }
    i = last + 1;
  }
  return text;
}

}  // namespace optique::config
