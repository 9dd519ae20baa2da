#include "scene/viewer_path.h"

#include <cassert>
#include <cmath>

namespace optique::scene {
namespace {

glm::dvec3 vec(const google::protobuf::RepeatedField<double>& v) {
  assert(v.size() == 3);
  return {v[0], v[1], v[2]};
}

}  // namespace

PathSpot path_spot(const std::vector<double>& times, double seconds) {
  assert(!times.empty());
  const int last = static_cast<int>(times.size()) - 1;
  if (last == 0) return {};
  const double start = times.front();
  const double duration = times.back() - start;
  assert(duration > 0.0);
  double t = std::fmod(seconds - start, duration);
  if (t < 0.0) t += duration;
  t += start;
  for (int i = 1; i <= last; ++i) {
    if (t <= times[i]) return {i - 1, i, (t - times[i - 1]) / (times[i] - times[i - 1])};
  }
  return {last, last, 0.0};
}

glm::dvec3 eye_at(const config::Viewer& viewer, double seconds) {
  if (viewer.path().empty()) return vec(viewer.eye());
  const auto& path = viewer.path();
  std::vector<double> times;
  for (const auto& point : path) times.push_back(point.time());
  const PathSpot spot = path_spot(times, seconds);
  return vec(path[spot.from].position()) * (1.0 - spot.fraction) + vec(path[spot.to].position()) * spot.fraction;
}

}  // namespace optique::scene
