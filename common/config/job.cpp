#include "config/job.h"

#include <cassert>
#include <cmath>

#include "config/projector_groups.h"

namespace optique::config {

ProjectorJob job_for(const Installation& installation, std::size_t projector) {
  assert(projector < installation.projectors.size());
  const Projector& self = installation.projectors[projector];
  ProjectorJob job;
  Installation& part = job.installation;
  part.screens.push_back(installation.screen_of(self));
  for (const Projector& other : installation.projectors) {
    if (!same_blend_group(other, self)) continue;
    if (other.id == self.id) job.projector = part.projectors.size();
    part.projectors.push_back(other);
    part.projectors.back().screen = 0;
  }
  part.viewer = installation.viewer;
  // A tracked head and the navigation reach the node in the scene state; the
  // tracker and the flystick are the master's.
  part.viewer.tracking.reset();
  part.viewer.navigation.reset();
  part.scene = installation.scene;
  if (installation.depth_of_field) {
    DepthOfField range;
    range.near = installation.depth_of_field->near;
    range.far = installation.depth_of_field->far;
    range.inset_radius = installation.depth_of_field->inset_radius;
    part.depth_of_field = range;
  }
  return job;
}

void scale_pixels(Projector& projector, double factor) {
  assert(factor > 0.0);
  projector.homography = glm::dmat3(factor, 0.0, 0.0, 0.0, factor, 0.0, 0.0, 0.0, 1.0) * projector.homography;
  projector.width = static_cast<int>(std::lround(projector.width * factor));
  projector.height = static_cast<int>(std::lround(projector.height * factor));
  projector.region.reset();  // the homography says where it lands
}

ProjectorJob supersampled(ProjectorJob job, int factor) {
  assert(factor >= 1);
  scale_pixels(job.installation.projectors[job.projector], factor);
  return job;
}

}  // namespace optique::config
