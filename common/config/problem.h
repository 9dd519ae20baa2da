#pragma once
// One thing wrong with a config, where it is: what the checks of config/ collect,
// all of them at once, so a user can fix a file in one go.

#include <string>
#include <vector>

namespace optique::config {

struct Problem {
  std::string path;     // e.g. "projectors[2].region.width"
  std::string message;  // e.g. "must be > 0 (got -1)"
};

// One line per problem: "ORIGIN: PATH: MESSAGE".
[[nodiscard]] std::string describe_problems(const std::vector<Problem>& problems, const std::string& origin);

}  // namespace optique::config
