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
  const PathSpot spot = path_spot(
      path.size(), [&](int i) { return path[i].time(); }, seconds);
  return vec(path[spot.from].position()) * (1.0 - spot.fraction) + vec(path[spot.to].position()) * spot.fraction;
}

}  // namespace optique::scene
