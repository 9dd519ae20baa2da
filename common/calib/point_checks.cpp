#include "calib/point_checks.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <tuple>

namespace optique::calib {
namespace {

enum class Side { kScreen, kPixel };

const char* side_name(Side side) { return side == Side::kScreen ? "screen" : "pixel"; }
const char* unit(Side side) { return side == Side::kScreen ? "m" : "px"; }
glm::dvec2 at(const geometry::Correspondence& c, Side side) { return side == Side::kScreen ? c.screen : c.pixel; }

double cross(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Distance of `x` from the line through `p` and `q` (p ≠ q).
double distance_from_line(const glm::dvec2& p, const glm::dvec2& q, const glm::dvec2& x) {
  const glm::dvec2 d = q - p;
  return std::abs(cross(d, x - p)) / std::hypot(d.x, d.y);
}

double extent(std::span<const geometry::Correspondence> points, Side side) {
  glm::dvec2 low = at(points.front(), side);
  glm::dvec2 high = low;
  for (const auto& c : points) {
    low = glm::min(low, at(c, side));
    high = glm::max(high, at(c, side));
  }
  return std::hypot(high.x - low.x, high.y - low.y);
}

// Three points as a line through the two farthest apart and the third one's
// distance from it.
struct Triple {
  std::array<std::size_t, 3> index;  // the two ends, then the middle one
  double distance = 0.0;
  double span = 0.0;
};

Triple measure_triple(std::span<const geometry::Correspondence> points, std::array<std::size_t, 3> idx, Side side) {
  const auto p = [&](std::size_t k) { return at(points[idx[k]], side); };
  const std::array<std::array<std::size_t, 3>, 3> orders{{{0, 1, 2}, {0, 2, 1}, {1, 2, 0}}};
  Triple best;
  for (const auto& o : orders) {
    const glm::dvec2 d = p(o[1]) - p(o[0]);
    const double span = std::hypot(d.x, d.y);
    if (span > best.span) {
      best.span = span;
      best.index = {idx[o[0]], idx[o[1]], idx[o[2]]};
      best.distance = span > 0.0 ? distance_from_line(p(o[0]), p(o[1]), p(o[2])) : 0.0;
    }
  }
  return best;
}

// If all points, or all but one, lie within kOnLineRelative of one line: the
// index of the one off it (nullopt when none is), and the worst distance of the
// others. Two of any three points are on such a line, so the candidates are
// the lines through the pairs among the first three points.
struct OnLine {
  std::optional<std::size_t> off;
  double distance = 0.0;
};

std::optional<OnLine> all_but_one_on_a_line(std::span<const geometry::Correspondence> points, Side side) {
  const double tolerance = kOnLineRelative * extent(points, side);
  const std::array<std::array<std::size_t, 2>, 3> pairs{{{0, 1}, {0, 2}, {1, 2}}};
  for (const auto& pair : pairs) {
    const glm::dvec2 p = at(points[pair[0]], side);
    const glm::dvec2 q = at(points[pair[1]], side);
    if (p == q) continue;
    OnLine result;
    std::size_t off_count = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double d = distance_from_line(p, q, at(points[i], side));
      if (d > tolerance) {
        ++off_count;
        result.off = i;
      } else {
        result.distance = std::max(result.distance, d);
      }
    }
    if (off_count <= 1) return result;
  }
  return std::nullopt;
}

std::string names(std::span<const std::size_t> indices) {
  std::string text;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (k > 0) text += k + 1 == indices.size() ? " and " : ", ";
    text += fmt::format("points[{}]", indices[k]);
  }
  return text;
}

}  // namespace

Result<void> check_points(std::span<const geometry::Correspondence> points) {
  if (points.size() < 4) {
    return Error{fmt::format("a homography needs at least 4 correspondences (got {})", points.size())};
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& c = points[i];
    if (!std::isfinite(c.screen.x) || !std::isfinite(c.screen.y)) {
      return Error{fmt::format("points[{}] has a non-finite screen coordinate ({}, {})", i, c.screen.x, c.screen.y)};
    }
    if (!std::isfinite(c.pixel.x) || !std::isfinite(c.pixel.y)) {
      return Error{fmt::format("points[{}] has a non-finite pixel coordinate ({}, {})", i, c.pixel.x, c.pixel.y)};
    }
  }
  // Repeats by sorting, so that hundreds of points cost no more than the fit.
  std::vector<std::size_t> order(points.size());
  for (const Side side : {Side::kScreen, Side::kPixel}) {
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      const glm::dvec2 pa = at(points[a], side);
      const glm::dvec2 pb = at(points[b], side);
      return std::tie(pa.x, pa.y, a) < std::tie(pb.x, pb.y, b);
    });
    for (std::size_t k = 1; k < order.size(); ++k) {
      const glm::dvec2 p = at(points[order[k]], side);
      if (p == at(points[order[k - 1]], side)) {
        return Error{fmt::format("points[{}] repeats points[{}] (the same {} position ({}, {}))", order[k],
                                 order[k - 1], side_name(side), p.x, p.y)};
      }
    }
  }
  for (const Side side : {Side::kPixel, Side::kScreen}) {  // pixels first: they were measured
    const auto on_line = all_but_one_on_a_line(points, side);
    if (!on_line) continue;
    const double span = extent(points, side);
    if (!on_line->off) {
      return Error{
          fmt::format("the {} points all lie on one line (within {:.3g} {} across {:.4g} {}): they fix no "
                      "homography",
                      side_name(side), on_line->distance, unit(side), span, unit(side))};
    }
    std::vector<std::size_t> others;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (i != *on_line->off) others.push_back(i);
    }
    const std::string which =
        points.size() == 4 ? names(others) + " lie" : fmt::format("all points but points[{}] lie", *on_line->off);
    return Error{
        fmt::format("{} on one line on the {} side (within {:.3g} {} across {:.4g} {}): no 4 points are in "
                    "general position, so they fix no homography; add points off that line",
                    which, side_name(side), on_line->distance, unit(side), span, unit(side))};
  }
  return {};
}

std::vector<std::string> near_line_warnings(std::span<const geometry::Correspondence> points) {
  std::vector<std::string> warnings;
  if (points.size() > kNearLineMaxPoints) return warnings;
  for (std::size_t a = 0; a < points.size(); ++a) {
    for (std::size_t b = a + 1; b < points.size(); ++b) {
      for (std::size_t c = b + 1; c < points.size(); ++c) {
        // Pixels first: a projective map keeps lines, so three points near one
        // on the screen are near one in the pixels too, and pixels are what was measured.
        for (const Side side : {Side::kPixel, Side::kScreen}) {
          const Triple t = measure_triple(points, {a, b, c}, side);
          if (t.distance > kNearLineRelative * t.span) continue;
          const std::array<std::size_t, 3> sorted{a, b, c};
          warnings.push_back(fmt::format(
              "{} are nearly on one line on the {} side: points[{}] is {:.3g} {} from the line through the other two, "
              "{:.4g} {} apart; with {} points the fit is fragile across that line: add points away from it",
              names(sorted), side_name(side), t.index[2], t.distance, unit(side), t.span, unit(side), points.size()));
          break;  // one warning per triple
        }
      }
    }
  }
  return warnings;
}

bool has_three_on_a_line(std::span<const geometry::Correspondence> points, double relative) {
  for (std::size_t a = 0; a < points.size(); ++a) {
    for (std::size_t b = a + 1; b < points.size(); ++b) {
      for (std::size_t c = b + 1; c < points.size(); ++c) {
        for (const Side side : {Side::kScreen, Side::kPixel}) {
          const Triple t = measure_triple(points, {a, b, c}, side);
          if (t.distance <= relative * t.span) return true;
        }
      }
    }
  }
  return false;
}

}  // namespace optique::calib
