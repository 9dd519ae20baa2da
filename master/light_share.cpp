#include "master/light_share.h"

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

std::string_view trim(std::string_view text) {
  constexpr std::string_view kSpace = " \t\r\n\f\v";
  const auto first = text.find_first_not_of(kSpace);
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(kSpace);
  return text.substr(first, last - first + 1);
}

// A whole decimal number, digits only (no sign), or nothing.
std::optional<std::uint64_t> parse_index(std::string_view text) {
  if (text.empty() || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size()) return std::nullopt;  // too large
  return value;
}

// `text` in double quotes. Built by appending: GCC 12 warns falsely (-Wrestrict)
// on "literal" + std::string.
std::string quoted(std::string_view text) {
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

Result<std::vector<std::uint32_t>> parse_light_list(std::string_view text, std::size_t light_count) {
  assert(light_count <= std::size_t{1} << 32);  // indices are 32-bit
  std::vector<std::uint32_t> lights;
  if (trim(text).empty()) return lights;
  std::vector<bool> listed(light_count, false);
  std::size_t item_number = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string_view item = trim(text.substr(start, comma - start));
    start = comma + 1;
    ++item_number;
    if (item.empty()) {
      return Error{"item " + std::to_string(item_number) + " of the light list " + quoted(text) +
                   " is empty: remove the extra comma"};
    }
    const std::size_t dash = item.find('-');
    const auto low = parse_index(trim(item.substr(0, dash)));
    const auto high = dash == std::string_view::npos ? low : parse_index(trim(item.substr(dash + 1)));
    if (!low || !high) {
      return Error{quoted(item) + " in the light list is not a light index or range (write 7 or 7-9)"};
    }
    if (*high < *low) {
      return Error{"the range " + quoted(item) + " is reversed: write " +
                   quoted(std::to_string(*high) + '-' + std::to_string(*low))};
    }
    if (*high >= light_count) {
      const std::string what = *low == *high ? "light " + std::to_string(*high) + " does not exist"
                                             : "lights " + std::string(item) + " do not all exist";
      return Error{what + ": " + scene_lights(light_count)};
    }
    for (std::uint64_t light = *low; light <= *high; ++light) {
      if (listed[light]) return Error{"light " + std::to_string(light) + " is listed twice"};
      listed[light] = true;
      lights.push_back(static_cast<std::uint32_t>(light));
    }
  }
  std::sort(lights.begin(), lights.end());
  return lights;
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

}  // namespace optique::master
