#pragma once
// Lists of the scene's lights as configs write them: indices and ranges, "0-6" or
// "0, 3, 7-9". A role-"lights" projector's lights and a light switch's "off" and
// "on" are such lists. The syntax is checked when the config is read; whether the
// scene has those lights, once the scene is loaded.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "util/result.h"

namespace optique::config {

// More lights than any scene may have: a list that goes beyond is a typo, and a
// range up to 4 billion would take minutes to expand.
inline constexpr std::uint32_t kMaxLights = 1u << 16;

// Ascending unique indices (whitespace allowed around items and dashes; blank
// text is the empty list). Each error names the offending item: an empty item,
// one that is not a number or range, a reversed range ("6-2"), an index listed
// twice, an index of kMaxLights or more.
[[nodiscard]] Result<std::vector<std::uint32_t>> parse_light_list(std::string_view text);

// Why `lights` (ascending) does not fit a scene of `light_count` lights ("light 24
// does not exist: the scene has 20 lights (0-19)"), or nothing when it does.
[[nodiscard]] std::optional<std::string> lights_beyond(std::span<const std::uint32_t> lights, std::size_t light_count);

// Ascending unique indices, runs as ranges: "0-6, 9"; the empty list as "".
// parse_light_list reads it back.
[[nodiscard]] std::string format_light_list(std::span<const std::uint32_t> lights);

}  // namespace optique::config
