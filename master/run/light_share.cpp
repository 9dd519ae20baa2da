#include "master/run/light_share.h"

#include <algorithm>
#include <cassert>
#include <charconv>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>

namespace optique::master {
namespace {

[[maybe_unused]] bool valid_inputs(std::span<const double> light_costs, std::span<const double> node_pixels,
                                   double base_cost, double ambient_cost) {
  const auto finite_non_negative = [](double x) { return std::isfinite(x) && x >= 0.0; };
  return !node_pixels.empty() &&
         std::all_of(node_pixels.begin(), node_pixels.end(), [](double p) { return std::isfinite(p) && p > 0.0; }) &&
         std::all_of(light_costs.begin(), light_costs.end(), finite_non_negative) && finite_non_negative(base_cost) &&
         finite_non_negative(ambient_cost);
}

double effective_cost(double coverage) { return std::max(coverage, kLightCostFloor); }

// The node whose modelled time is least after adding `cost` per pixel. Times
// within a relative 1e-12 of each other count as equal, so that rounding in the
// sums cannot break a tie the model calls a tie: those go to the lowest index.
std::size_t least_after(std::span<const double> times, std::span<const double> node_pixels, double cost) {
  std::size_t best = 0;
  double best_time = times[0] + node_pixels[0] * cost;
  for (std::size_t i = 1; i < times.size(); ++i) {
    const double time = times[i] + node_pixels[i] * cost;
    if (time < best_time - 1e-12 * best_time) {
      best = i;
      best_time = time;
    }
  }
  return best;
}

}  // namespace

std::vector<LightShare> share_lights(std::span<const double> light_costs, std::span<const double> node_pixels,
                                     double base_cost, double ambient_cost) {
  assert(valid_inputs(light_costs, node_pixels, base_cost, ambient_cost));
  std::vector<double> times(node_pixels.size());
  std::transform(node_pixels.begin(), node_pixels.end(), times.begin(),
                 [base_cost](double pixels) { return pixels * base_cost; });
  std::vector<LightShare> shares(node_pixels.size());

  const std::size_t carrier = least_after(times, node_pixels, ambient_cost);
  shares[carrier].ambient = true;
  times[carrier] += node_pixels[carrier] * ambient_cost;

  // Largest first: the small ones placed last even out what the large ones left.
  std::vector<std::uint32_t> order(light_costs.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    return effective_cost(light_costs[a]) > effective_cost(light_costs[b]);
  });
  for (const std::uint32_t light : order) {
    const double cost = effective_cost(light_costs[light]);
    const std::size_t node = least_after(times, node_pixels, cost);
    shares[node].lights.push_back(light);
    times[node] += node_pixels[node] * cost;
  }
  for (LightShare& share : shares) std::sort(share.lights.begin(), share.lights.end());
  return shares;
}

std::vector<double> modelled_times(std::span<const double> light_costs, std::span<const double> node_pixels,
                                   double base_cost, double ambient_cost, std::span<const LightShare> shares) {
  assert(valid_inputs(light_costs, node_pixels, base_cost, ambient_cost));
  assert(shares.size() == node_pixels.size());
  std::vector<double> times(node_pixels.size());
  for (std::size_t i = 0; i < node_pixels.size(); ++i) {
    double per_pixel = base_cost + (shares[i].ambient ? ambient_cost : 0.0);
    for (const std::uint32_t light : shares[i].lights) {
      assert(light < light_costs.size());
      per_pixel += effective_cost(light_costs[light]);
    }
    times[i] = node_pixels[i] * per_pixel;
  }
  return times;
}

}  // namespace optique::master
