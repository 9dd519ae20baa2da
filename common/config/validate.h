#pragma once
// Checks an installation as its file (or a welcome) gives it, before it is built
// into typed values (config/parse.h): unique ids, references that exist, positive
// sizes, finite numbers, known names, light lists that parse. Every problem names the field path
// ("projectors[2].screen") and says what is wrong; all problems are reported at
// once so a user can fix a config in one go.

#include <string>
#include <vector>

#include "config/color_fields.h"
#include "config/problem.h"
#include "config/response.h"
#include "config/tracking.h"
#include "config/up_conversion.h"
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

// The sections the check builds to check them (a projector's response, colour
// fields and up-conversion, the viewer's tracking), kept for the build
// (config/parse.cpp), which takes them instead of building them again. Each is
// whole where no problem names it.
struct CheckedSections {
  std::vector<ProjectorResponse> responses;  // one per projector
  std::vector<ColorFields> color_fields;
  std::vector<UpConversion> up_conversion;
  std::optional<Tracking> tracking;
};
[[nodiscard]] std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir,
                                            Scope scope, CheckedSections& sections);

}  // namespace optique::config
