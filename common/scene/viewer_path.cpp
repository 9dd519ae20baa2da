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

glm::dvec3 eye_at(const config::Viewer& viewer, double seconds) {
  if (viewer.path().empty()) return vec(viewer.eye());
  const auto& path = viewer.path();
  if (path.size() == 1) return vec(path[0].position());
  const double start = path[0].time();
  const double duration = path[path.size() - 1].time() - start;
  assert(duration > 0.0);
  double t = std::fmod(seconds - start, duration);
  if (t < 0.0) t += duration;
  t += start;
  for (int i = 1; i < path.size(); ++i) {
    if (t <= path[i].time()) {
      const double span = path[i].time() - path[i - 1].time();
      const double a = (t - path[i - 1].time()) / span;
      return vec(path[i - 1].position()) * (1.0 - a) + vec(path[i].position()) * a;
    }
  }
  return vec(path[path.size() - 1].position());
}

}  // namespace optique::scene
