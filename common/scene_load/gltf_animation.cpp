#include "scene_load/gltf_animation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>

#include "scene/definition.h"
#include "util/finite.h"

namespace optique::scene::gltf {

using util::finite;

glm::dvec4 Sampler::at(double t) const {
  const std::size_t n = times.size();
  if (n == 1 || t <= times.front()) return key(0);
  if (t >= times.back()) return key(n - 1);
  const auto upper = std::upper_bound(times.begin(), times.end(), t);
  const auto k = static_cast<std::size_t>(upper - times.begin()) - 1;  // times[k] <= t < times[k + 1]
  const double span = times[k + 1] - times[k];
  const double u = (t - times[k]) / span;
  switch (interpolation) {
    case Interpolation::kStep:
      return key(k);
    case Interpolation::kLinear: {
      if (!rotation) return glm::mix(key(k), key(k + 1), u);
      const glm::dvec4 a = key(k);
      const glm::dvec4 b = key(k + 1);
      const glm::dquat q =
          glm::normalize(glm::slerp(glm::dquat(a.w, a.x, a.y, a.z), glm::dquat(b.w, b.x, b.y, b.z), u));
      return {q.x, q.y, q.z, q.w};
    }
    case Interpolation::kCubicSpline: {
      const double u2 = u * u;
      const double u3 = u2 * u;
      const glm::dvec4 value =
          (2.0 * u3 - 3.0 * u2 + 1.0) * element(3 * k + 1) + (u3 - 2.0 * u2 + u) * span * element(3 * k + 2) +
          (-2.0 * u3 + 3.0 * u2) * element(3 * (k + 1) + 1) + (u3 - u2) * span * element(3 * (k + 1));
      if (!rotation) return value;
      const double length = glm::length(value);
      if (!(length > 1e-12) || !std::isfinite(length)) return u < 0.5 ? key(k) : key(k + 1);
      return value / length;
    }
  }
  return key(k);
}

glm::dmat4 Link::local_at(double t) const {
  if (!animated) return fixed;
  glm::dvec3 position = translation;
  glm::dquat turn = rotation;
  glm::dvec3 size = scale;
  if (translation_track) position = glm::dvec3(translation_track->at(t));
  if (rotation_track) {
    const glm::dvec4 q = rotation_track->at(t);
    turn = glm::dquat(q.w, q.x, q.y, q.z);
  }
  if (scale_track) size = glm::dvec3(scale_track->at(t));
  return glm::translate(glm::dmat4(1.0), position) * glm::mat4_cast(turn) * glm::scale(glm::dmat4(1.0), size);
}

void Link::key_times(std::vector<double>& out) const {
  for (const auto* track : {&translation_track, &rotation_track, &scale_track}) {
    if (*track) out.insert(out.end(), (*track)->times.begin(), (*track)->times.end());
  }
}

double Track::wrap(double t) const {
  if (!std::isfinite(t) || !(duration > 0.0)) return 0.0;
  double local = std::fmod(t, duration);
  if (local < 0.0) local += duration;
  if (!(local < duration) || local < 0.0) local = 0.0;
  return local;
}

glm::dmat4 Track::world_at(double local_time) const {
  glm::dmat4 world = base;
  for (const auto& link : links) world = world * link.local_at(local_time);
  return world;
}

Pose Track::pose_at(double t) const {
  const Pose pose = decompose(world_at(wrap(t)));
  return finite(pose) ? pose : fallback;
}

bool finite(const Pose& pose) { return finite(pose.position) && finite(pose.scale) && finite(pose.rotation); }

glm::dquat canonical(glm::dquat q) {
  q = glm::normalize(q);
  if (q.w < 0.0) q = -q;
  return q;
}

glm::dquat rotation_between(const glm::dvec3& from, const glm::dvec3& to) {
  const double d = glm::dot(from, to);
  if (d < -1.0 + 1e-12) {
    const glm::dvec3 other = std::abs(from.x) < 0.9 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
    return glm::angleAxis(std::numbers::pi, glm::normalize(glm::cross(from, other)));
  }
  const glm::dvec3 c = glm::cross(from, to);
  return glm::normalize(glm::dquat(1.0 + d, c.x, c.y, c.z));
}

Pose decompose(const glm::dmat4& m) {
  Pose pose;
  pose.position = glm::dvec3(m[3]);
  glm::dvec3 axes[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
  glm::dvec3 scale(glm::length(axes[0]), glm::length(axes[1]), glm::length(axes[2]));
  if (glm::dot(axes[0], glm::cross(axes[1], axes[2])) < 0.0) scale.x = -scale.x;
  const double largest = std::max({std::abs(scale.x), std::abs(scale.y), std::abs(scale.z)});
  const double tiny = 1e-12 * largest;
  int collapsed = -1;
  int collapsed_count = 0;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(scale[i]) > tiny && largest > 0.0) {
      axes[i] /= scale[i];
    } else {
      collapsed = i;
      ++collapsed_count;
    }
  }
  if (collapsed_count == 1) {
    const auto& a = axes[(collapsed + 1) % 3];
    const auto& b = axes[(collapsed + 2) % 3];
    axes[collapsed] = glm::normalize(glm::cross(a, b));
  }
  if (collapsed_count <= 1) {
    pose.rotation = canonical(glm::quat_cast(glm::dmat3(axes[0], axes[1], axes[2])));
  } else if (collapsed_count == 2) {
    for (int i = 0; i < 3; ++i) {
      if (std::abs(scale[i]) > tiny && largest > 0.0) {
        glm::dvec3 unit(0.0);
        unit[i] = 1.0;
        pose.rotation = canonical(rotation_between(unit, glm::normalize(axes[i])));
      }
    }
  }
  pose.scale = scale;
  return pose;
}

bool reproduces(const Pose& pose, const glm::dmat4& m) {
  const glm::dmat4 back = model_matrix(pose);
  double largest = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) largest = std::max(largest, std::abs(m[c][r]));
  }
  const double tolerance = 1e-6 * largest;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) {
      if (!(std::abs(back[c][r] - m[c][r]) <= tolerance)) return false;
    }
  }
  for (int c = 0; c < 4; ++c) {
    if (!(std::abs(m[c][3] - (c == 3 ? 1.0 : 0.0)) <= 1e-9)) return false;
  }
  return true;
}

}  // namespace optique::scene::gltf
