#pragma once
// Scripted paths: points at increasing times, interpolated linearly and looped
// over their duration. The viewer's eye, the focal depth and the gaze point all
// follow such paths.

#include <cassert>
#include <cmath>

namespace optique::scene {

// Where `seconds` falls on a looped path of `count` points whose times
// (`time_of(i)`, increasing) a config gives: between point `from` and point `to`,
// `fraction` of the way. One point: 0, 0, 0. Called every frame: reads the
// times where they are, copying nothing.
struct PathSpot {
  int from = 0;
  int to = 0;
  double fraction = 0.0;
};
template <class TimeOf>
[[nodiscard]] PathSpot path_spot(int count, const TimeOf& time_of, double seconds) {
  assert(count > 0);
  const int last = count - 1;
  if (last == 0) return {};
  const double start = time_of(0);
  const double duration = time_of(last) - start;
  assert(duration > 0.0);
  double t = std::fmod(seconds - start, duration);
  if (t < 0.0) t += duration;
  t += start;
  for (int i = 1; i <= last; ++i) {
    if (t <= time_of(i)) return {i - 1, i, (t - time_of(i - 1)) / (time_of(i) - time_of(i - 1))};
  }
  return {last, last, 0.0};
}

// The value of a looped path of points (each with a `time`) at `seconds`:
// `value_of` of the points around it, linearly between them.
template <class Points, class ValueOf>
[[nodiscard]] auto path_value(const Points& path, double seconds, const ValueOf& value_of) {
  const PathSpot spot = path_spot(
      static_cast<int>(path.size()), [&](int i) { return path[static_cast<std::size_t>(i)].time; }, seconds);
  return value_of(path[static_cast<std::size_t>(spot.from)]) * (1.0 - spot.fraction) +
         value_of(path[static_cast<std::size_t>(spot.to)]) * spot.fraction;
}

}  // namespace optique::scene
