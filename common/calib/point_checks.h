#pragma once
// Checks on the correspondences before any fit: the sets that leave a homography
// undetermined (errors) and the nearly degenerate ones that make it fragile
// (warnings). Every message names the points and the measured reason.

#include <span>
#include <string>
#include <vector>

#include "geometry/homography.h"
#include "util/result.h"

namespace optique::calib {

// Three points closer to a line than this fraction of their span count as on it:
// far below any measurement noise, so only exactly degenerate input is refused.
inline constexpr double kOnLineRelative = 1e-9;
// Three points closer to a line than this fraction of their span, when they are
// half the set or more, make the homography fragile across that line.
inline constexpr double kNearLineRelative = 1e-3;
// Up to this many points, three of them are half the set: near lines are checked.
inline constexpr std::size_t kNearLineMaxPoints = 6;

// Errors: fewer than 4 points, a non-finite coordinate, a repeated point, all
// points or all but one on one line (on the screen or in the pixels): then no 4
// of them are in general position and they fix no homography.
[[nodiscard]] Result<void> check_points(std::span<const geometry::Correspondence> points);

// Warnings for three points nearly on one line (screen or pixel side), checked
// when the set is small (kNearLineMaxPoints) so that the three are a large part of it.
[[nodiscard]] std::vector<std::string> near_line_warnings(std::span<const geometry::Correspondence> points);

// Whether three of these points are on one line within `relative` of their span
// on either side: RANSAC skips such minimal samples.
[[nodiscard]] bool has_three_on_a_line(std::span<const geometry::Correspondence> points, double relative);

}  // namespace optique::calib
