#pragma once
// Whether every component of a glm vector, matrix or quaternion is a finite
// number: what input (scene files, deltas, fits) must pass before it reaches a
// transform, since one NaN spreads through every product after it.

#include <cmath>

#include <glm/fwd.hpp>

namespace optique::util {

template <glm::length_t L, typename T, glm::qualifier Q>
[[nodiscard]] bool finite(const glm::vec<L, T, Q>& v) {
  for (glm::length_t i = 0; i < L; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

template <glm::length_t C, glm::length_t R, typename T, glm::qualifier Q>
[[nodiscard]] bool finite(const glm::mat<C, R, T, Q>& m) {
  for (glm::length_t c = 0; c < C; ++c) {
    if (!finite(m[c])) return false;
  }
  return true;
}

template <typename T, glm::qualifier Q>
[[nodiscard]] bool finite(const glm::qua<T, Q>& q) {
  return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}

}  // namespace optique::util
