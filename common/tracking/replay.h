#pragma once
// A recorded head path for tracking's `replay` source: a CSV file of time
// (seconds, increasing by 1 ms at least; the first is the start), the head's position x, y, z (metres,
// tracker space) and its orientation qw, qx, qy, qz (a unit quaternion, head →
// tracker space), one sample a row. A first row that is not numbers is a header;
// blank lines and lines starting with # are skipped. Looped over its last time.

#include <string>
#include <string_view>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "util/result.h"

namespace optique::tracking {

struct ReplaySample {
  double time = 0.0;  // seconds
  glm::dvec3 position{0.0};
  glm::dquat orientation{1.0, 0.0, 0.0, 0.0};
};

inline constexpr std::size_t kMostReplaySamples = 10'000'000;

// `name` says where the text came from in messages ("head.csv").
[[nodiscard]] Result<std::vector<ReplaySample>> parse_replay(std::string_view text, const std::string& name);
[[nodiscard]] Result<std::vector<ReplaySample>> load_replay(const std::string& path);

}  // namespace optique::tracking
