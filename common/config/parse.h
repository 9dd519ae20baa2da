#pragma once
// From the file's schema (or a welcome's) to the typed installation: every
// problem checked at once (config/validate.h), then built with the defaults
// applied (here, and only here), screen references resolved, and every
// projector's homography known: from the config, a calibration file, a camera
// view shared with a partner (A₂₁ = A₂c⁻¹ · A₁c), or a region.

#include <string>
#include <string_view>

#include "config/installation.h"
#include "config/job.h"
#include "config/validate.h"
#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

// `config_dir` resolves relative paths (the glTF scene, calibration files);
// `origin` names the source in messages ("configs/wall.json: projectors[2].width: …").
[[nodiscard]] Result<Installation> parse_installation(const schema::Installation& installation,
                                                      const std::string& config_dir, const std::string& origin);

// Checked like a config file (Scope::job), so that a bad welcome is refused with
// the field that is wrong; fails too when `projector_id` is not among the
// projectors or not on the screen.
[[nodiscard]] Result<ProjectorJob> parse_job(const schema::Installation& job, std::string_view projector_id,
                                             const std::string& origin);

}  // namespace optique::config
