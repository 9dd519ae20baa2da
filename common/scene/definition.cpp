#include "scene/definition.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace optique::scene {

glm::dmat4 model_matrix(const Pose& pose) {
  return glm::translate(glm::dmat4(1.0), pose.position) * glm::mat4_cast(pose.rotation) *
         glm::scale(glm::dmat4(1.0), pose.scale);
}

Pose interpolate(const ObjectState& object, double fraction) {
  Pose pose;
  pose.position = glm::mix(object.now.position, object.next.position, fraction);
  pose.scale = glm::mix(object.now.scale, object.next.scale, fraction);
  pose.rotation = glm::slerp(object.now.rotation, object.next.rotation, fraction);
  return pose;
}

}  // namespace optique::scene
