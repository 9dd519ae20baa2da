#pragma once
// The automatic light split of a stacked group (DESIGN.md, "Lighting split"):
// each light drawn by exactly one node, the ambient and emissive terms by exactly
// one, so that the projectors' optical sum is the full render. Pure partitioning
// and the role-"lights" list syntax; no IO.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "util/result.h"

namespace optique::master {

struct LightShare {
  std::vector<std::uint32_t> lights;  // indices into the scene's lights, ascending
  bool ambient = false;               // also draws the ambient and emissive terms

  friend bool operator==(const LightShare&, const LightShare&) = default;
};

// The least cost a light counts for, whatever its coverage: a light that reaches
// none of a node's pixels still costs each of them a turn of the shader's light
// loop (a few instructions before its early `continue`), so n such lights are not
// free. In units of a light that reaches every pixel.
inline constexpr double kLightCostFloor = 0.1;

// Shares the lights out among the nodes of a stacked group so that they finish
// together. Node i's frame time is modelled as
//   node_pixels[i] · (base_cost + Σ max(cost, kLightCostFloor) over its lights
//                     + ambient_cost if it carries the ambient),
// light costs being their light_coverage (scene/light_coverage.h) for the
// group's screen area. Greedy longest-processing-time: the ambient first, to the
// node that is fastest alone; then the lights by decreasing cost (equal costs by
// index), each to the node whose modelled time after taking it is least; ties to
// the lowest node index. Deterministic. One share per node, in node order; every
// light in exactly one, the ambient in exactly one.
// Preconditions (asserted): node_pixels non-empty and all > 0 and finite; costs
// finite and ≥ 0.
[[nodiscard]] std::vector<LightShare> share_lights(std::span<const double> light_costs,
                                                   std::span<const double> node_pixels, double base_cost,
                                                   double ambient_cost);

// The modelled frame time of each node for `shares` (one per node), in the
// model above: for logs, tests and the bench.
[[nodiscard]] std::vector<double> modelled_times(std::span<const double> light_costs,
                                                 std::span<const double> node_pixels, double base_cost,
                                                 double ambient_cost, std::span<const LightShare> shares);

// Parses a role-"lights" list of indices and ranges, "0-6" or "0, 3, 7-9"
// (whitespace allowed around items and dashes), into ascending unique indices.
// Blank text is the empty list. Each error names the offending item: an empty
// item, one that is not a number or range, a reversed range ("6-2"), an index the
// scene does not have, an index listed twice.
[[nodiscard]] Result<std::vector<std::uint32_t>> parse_light_list(std::string_view text, std::size_t light_count);

// Formats ascending unique indices compactly, runs as ranges: "0-6, 9"; the empty
// list as "". parse_light_list reads it back.
[[nodiscard]] std::string format_light_list(std::span<const std::uint32_t> lights);

}  // namespace optique::master
