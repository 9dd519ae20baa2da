#pragma once
// A glTF animation evaluated at any time: samplers (STEP, LINEAR with slerp for
// rotations, CUBICSPLINE), a node's local transform with any of its
// translation, rotation and scale animated, and an animated node's track from
// its nearest still ancestor down, giving the node's Pose at any time. Plain
// values, no tinygltf: an animated object's pose function owns a copy.

#include <cstddef>
#include <optional>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "scene/state.h"

namespace optique::scene::gltf {

enum class Interpolation { kStep, kLinear, kCubicSpline };

struct Sampler {
  Interpolation interpolation = Interpolation::kLinear;
  bool rotation = false;       // quaternions (x, y, z, w), else 3-vectors
  std::vector<double> times;   // strictly increasing
  std::vector<double> values;  // per key one element, or in-tangent, value, out-tangent for cubic splines

  [[nodiscard]] std::size_t width() const { return rotation ? 4 : 3; }
  [[nodiscard]] glm::dvec4 element(std::size_t i) const {
    const double* v = values.data() + i * width();
    return {v[0], v[1], v[2], rotation ? v[3] : 0.0};
  }
  [[nodiscard]] glm::dvec4 key(std::size_t k) const {
    return element(interpolation == Interpolation::kCubicSpline ? 3 * k + 1 : k);
  }
  // The value at `t`: before the first key the first value, after the last the
  // last. Quaternions come back unit length.
  [[nodiscard]] glm::dvec4 at(double t) const;
};

// A node's local transform: fixed, or translation/rotation/scale with any of
// them animated.
struct Link {
  bool animated = false;
  glm::dmat4 fixed{1.0};
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 scale{1.0};
  std::optional<Sampler> translation_track;
  std::optional<Sampler> rotation_track;
  std::optional<Sampler> scale_track;

  [[nodiscard]] glm::dmat4 local_at(double t) const;
  void key_times(std::vector<double>& out) const;  // of its tracks, appended
};

// Everything an animated object's pose needs: the world matrix of its nearest
// static ancestor and the local transforms from there down to the node.
struct Track {
  glm::dmat4 base{1.0};
  std::vector<Link> links;
  double duration = 0.0;  // all animations loop over this
  Pose fallback;          // the pose at t = 0, checked finite at load

  // `t` into [0, duration); 0 where it or the duration is not a number.
  [[nodiscard]] double wrap(double t) const;
  [[nodiscard]] glm::dmat4 world_at(double local_time) const;
  // The pose at `t` (wrapped); the fallback where it would not be finite.
  [[nodiscard]] Pose pose_at(double t) const;
};

[[nodiscard]] bool finite(const Pose& pose);
// Unit length, w ≥ 0.
[[nodiscard]] glm::dquat canonical(glm::dquat q);
// The rotation taking unit vector `from` to unit vector `to`.
[[nodiscard]] glm::dquat rotation_between(const glm::dvec3& from, const glm::dvec3& to);
// The pose whose model matrix is `m`, assuming `m` has no shear. A negative
// determinant becomes a negative x scale; an axis scaled to 0 takes its
// direction from the other two, or, where only one is left, the rotation is the
// shortest one onto that one.
[[nodiscard]] Pose decompose(const glm::dmat4& m);
// Whether `pose` reproduces `m`: the same linear part (to a millionth of its
// largest element: no shear) and an affine bottom row.
[[nodiscard]] bool reproduces(const Pose& pose, const glm::dmat4& m);

}  // namespace optique::scene::gltf
