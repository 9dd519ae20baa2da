#pragma once
// The typed installation written back as its schema: what the master sends a
// node in its welcome, and what tests write as config files. Resolved: every
// projector's geometry is a region or a homography (no calibration file, no
// camera view), the scene path is absolute, defaults are written out. So
// parse_installation(to_schema(x)) gives x back, but for where each homography
// came from.

#include "config/installation.h"
#include "optique/config.pb.h"

namespace optique::config {

[[nodiscard]] schema::Installation to_schema(const Installation& installation);

[[nodiscard]] schema::Screen to_schema(const Screen& screen);
// `screens`: the installation's, to name the projector's screen.
[[nodiscard]] schema::Projector to_schema(const Projector& projector, const std::vector<Screen>& screens);
[[nodiscard]] schema::Viewer to_schema(const Viewer& viewer);
[[nodiscard]] schema::Tracking to_schema(const Tracking& tracking);
[[nodiscard]] schema::Scene to_schema(const SceneSource& scene);
[[nodiscard]] schema::MasterSettings to_schema(const MasterSettings& master);
[[nodiscard]] schema::DepthOfField to_schema(const DepthOfField& depth_of_field, const std::vector<Screen>& screens);

}  // namespace optique::config
