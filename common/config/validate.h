#pragma once
// Checks an installation after parsing: unique ids, references that exist, positive
// sizes, finite numbers, known names. Every problem names the field path
// ("projectors[2].screen") and says what is wrong; all problems are reported at
// once so a user can fix a config in one go.

#include <string>
#include <vector>

#include "optique/config.pb.h"

namespace optique::config {

struct Problem {
  std::string path;     // e.g. "projectors[2].region.width"
  std::string message;  // e.g. "must be > 0 (got -1)"
};

// One line per problem: "ORIGIN: PATH: MESSAGE".
[[nodiscard]] std::string describe_problems(const std::vector<Problem>& problems, const std::string& origin);

// `config_dir` resolves relative asset paths (the glTF scene).
[[nodiscard]] std::vector<Problem> validate(const Installation& installation, const std::string& config_dir);

}  // namespace optique::config
