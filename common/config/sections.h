#pragma once
// The installation's sections, each checked and built in one pass from the
// file's schema (config/checker.h): what a section holds in itself is checked
// where it is built; what relates sections to one another is checked in one
// place, after them (check_across_sections); the projectors' homographies are
// resolved last, once everything they rest on is known to be right.
// config/parse.cpp runs them in that order.

#include <optional>
#include <string>
#include <vector>

#include "config/checker.h"
#include "config/installation.h"
#include "config/parse.h"
#include "optique/config.pb.h"

namespace optique::config {

// Where projector `i` is in the file: "projectors[i]".
[[nodiscard]] inline std::string projector_path(std::size_t i) { return "projectors[" + std::to_string(i) + "]"; }

[[nodiscard]] std::vector<Screen> parse_screens(const schema::Installation& installation, Checker& check);
// The screen a section names (the last of that id: a duplicate is a problem of its own).
[[nodiscard]] std::optional<std::size_t> find_screen(const std::vector<Screen>& screens, const std::string& id);
// A screen without an id is a problem of its own; a reference to a screen then
// cannot be judged, and "unknown screen" would only add noise.
[[nodiscard]] bool every_screen_named(const std::vector<Screen>& screens);

// Everything but the homographies of projectors given by a calibration file or
// a camera view (resolve_homographies). A reference to an unknown screen is a
// problem, and leaves the projector's `screen` at screens.size().
[[nodiscard]] std::vector<Projector> parse_projectors(const schema::Installation& installation,
                                                      const std::vector<Screen>& screens, const std::string& config_dir,
                                                      Checker& check);

[[nodiscard]] Viewer parse_viewer(const schema::Viewer& viewer, const std::string& config_dir, Checker& check);

// `config_dir` resolves master.api.assets.
[[nodiscard]] MasterSettings parse_master(const schema::MasterSettings& master, const std::string& config_dir,
                                          Checker& check);

[[nodiscard]] SceneSource parse_scene(const schema::Scene& scene, const std::string& config_dir, Scope scope,
                                      Checker& check);

// A whole installation's depth of field is checked in full when its projectors
// need one (`needed`); a job carries only what its node uses (the range), and
// the gaze only where its screen is among the job's.
[[nodiscard]] std::optional<DepthOfField> parse_depth_of_field(const schema::Installation& installation,
                                                               const std::vector<Screen>& screens, const Viewer& viewer,
                                                               Scope scope, bool needed, Checker& check);

// Whether the projectors are a focus/defocus pair, which needs a depth of field.
[[nodiscard]] bool needs_depth_of_field(const std::vector<Projector>& projectors);

// What relates two sections: stacked partners, colour-field presets and the
// frame rate, interpolation and a live head, a depth of field nothing uses.
void check_across_sections(const schema::Installation& installation, const Installation& built, Scope scope,
                           Checker& check);

// Every projector's homography from its calibration file or its camera view
// shared with a partner; then each must light part of its screen.
void resolve_homographies(const schema::Installation& installation, Installation& built, const std::string& config_dir,
                          std::vector<Problem>& problems);

}  // namespace optique::config
