#pragma once
// Every projector's homography, whichever way the config gave it: directly, a
// calibration file, a camera view shared with a partner (A₂₁ = A₂c⁻¹ · A₁c), or a
// region (an aligned projector). After resolve_geometry, every projector has
// either its region or its homography (a calibration file is read into it), so
// nodes need no files of the master's.

#include <string>
#include <vector>

#include "config/validate.h"
#include "geometry/projection.h"
#include "geometry/projector_geometry.h"
#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

// Fills Projector.homography where it comes from a file or a camera view, and checks that each one lights
// part of its screen. Runs on a validated installation with defaults applied.
[[nodiscard]] std::vector<Problem> resolve_geometry(Installation& installation, const std::string& config_dir);

// Whether two projectors light the same screen for the same eye: their light adds
// into one image, which the screen simulator composes.
[[nodiscard]] bool same_screen_image(const Projector& a, const Projector& b);

// Whether two projectors show the same share of the light (the same content role,
// lights and ambient): a layer of a stacked group, or all projectors of a plain
// wall. Projectors whose lights the master shares out ("auto") are each a layer.
[[nodiscard]] bool same_layer(const Projector& a, const Projector& b);

// Whether two projectors blend their overlaps with each other: the same screen
// image and the same layer. Stacked layers do not blend with each other: their
// light is meant to add.
[[nodiscard]] bool same_blend_group(const Projector& a, const Projector& b);

// The part of `screen` that `region` (metres in the screen's frame) covers, in
// world space; and the whole screen.
[[nodiscard]] geometry::WorldRect screen_region(const Screen& screen, const Region& region);
[[nodiscard]] geometry::WorldRect whole_screen(const Screen& screen);

// The screen area that is shown: the whole screen rectangle.
[[nodiscard]] geometry::ScreenRect usable_area(const Screen& screen);

// The geometry of a resolved projector: from its homography, or its region.
[[nodiscard]] Result<geometry::ProjectorGeometry> projector_geometry(const Projector& projector);

}  // namespace optique::config
