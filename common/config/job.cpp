#include "config/job.h"

#include <cassert>

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

ProjectorJob supersampled(ProjectorJob job, int factor) {
  assert(factor >= 1);
  Projector& p = job.installation.projectors[job.projector];
  const double f = factor;
  p.homography = glm::dmat3(f, 0.0, 0.0, 0.0, f, 0.0, 0.0, 0.0, 1.0) * p.homography;
  p.width *= factor;
  p.height *= factor;
  p.region.reset();  // the homography says where it lands
  return job;
}

}  // namespace optique::config
