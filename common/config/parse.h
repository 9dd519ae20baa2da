#pragma once
// From the file's schema (or a welcome's) to the typed installation, in one
// pass: each section checked and built at once (config/sections.h), with the
// defaults applied (there, and only there), screen references resolved, what
// relates sections checked, and every projector's homography known: from the
// config, a calibration file, a camera view shared with a partner
// (A₂₁ = A₂c⁻¹ · A₁c), or a region. Every problem names the field path
// ("projectors[2].screen") and says what is wrong; all are reported at once,
// so that a user can fix a config in one go.

#include <string>
#include <string_view>
#include <vector>

#include "config/installation.h"
#include "config/job.h"
#include "config/problem.h"
#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

// What is checked: a whole installation (a config file), or a node's share of
// one as its welcome carries it, where what spans the installation is not there
// to check (stacked partners, the gaze's screen, how the focal depth is set, the
// scene file, which the node loads itself).
enum class Scope { installation, job };

// `config_dir` resolves relative paths (the glTF scene, calibration files);
// `origin` names the source in messages ("configs/wall.json: projectors[2].width: …").
[[nodiscard]] Result<Installation> parse_installation(const schema::Installation& installation,
                                                      const std::string& config_dir, const std::string& origin);

// Checked like a config file (Scope::job), so that a bad welcome is refused with
// the field that is wrong; fails too when `projector_id` is not among the
// projectors or not on the screen.
[[nodiscard]] Result<ProjectorJob> parse_job(const schema::Installation& job, std::string_view projector_id,
                                             const std::string& origin);

// Only the problems parse_installation would report (none: it succeeds).
[[nodiscard]] std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir,
                                            Scope scope = Scope::installation);

}  // namespace optique::config
