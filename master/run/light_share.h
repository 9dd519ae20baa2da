#pragma once
// The automatic light split of a stacked group (Majumder & Welch, "Computer Graphics
// Optique"; docs/design.md, "The lighting split"):
// each light drawn by exactly one node, the ambient and emissive terms by exactly
// one, so that the projectors' optical sum is the full render. Pure partitioning;
// no IO. (The lists configs write are config/light_list.h.)

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/light_share.h"
#include "util/result.h"

namespace optique::master {

using protocol::LightShare;

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

}  // namespace optique::master
