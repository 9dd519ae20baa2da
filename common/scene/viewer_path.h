#pragma once
// Scripted paths: points at increasing times, interpolated linearly and looped
// over their duration. The viewer's eye, the focal depth and the gaze point all
// follow such paths.

#include <cassert>
#include <cmath>

#include <glm/vec3.hpp>

#include "optique/config.pb.h"

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

// The eye at simulation time `seconds`: the fixed eye, or the scripted path
// interpolated linearly between its points and looped over its duration.
// `viewer` must be validated (config::validate).
[[nodiscard]] glm::dvec3 eye_at(const config::Viewer& viewer, double seconds);

}  // namespace optique::scene
