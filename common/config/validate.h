#pragma once
// Checks an installation as its file (or a welcome) gives it, before it is built
// into typed values (config/parse.h): unique ids, references that exist, positive
// sizes, finite numbers, known names, light lists that parse. Every problem names the field path
// ("projectors[2].screen") and says what is wrong; all problems are reported at
// once so a user can fix a config in one go.

#include <string>
#include <vector>

#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::config {

// One line per problem: "ORIGIN: PATH: MESSAGE".
[[nodiscard]] std::string describe_problems(const std::vector<Problem>& problems, const std::string& origin);

// What is checked: a whole installation (a config file), or a node's share of
// one as its welcome carries it, where what spans the installation is not there
// to check (stacked partners, the gaze's screen, how the focal depth is set, the
// scene file, which the node loads itself).
enum class Scope { installation, job };

// `config_dir` resolves relative asset paths (the glTF scene, calibration files).
[[nodiscard]] std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir,
                                            Scope scope = Scope::installation);

}  // namespace optique::config
