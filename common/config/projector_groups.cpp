#include "config/projector_groups.h"

namespace optique::config {

bool same_screen_image(const Projector& a, const Projector& b) { return a.screen == b.screen && a.eye == b.eye; }

bool same_layer(const Projector& a, const Projector& b) {
  return a.content == b.content && !(a.content.role == ContentRole::lights && a.content.automatic);
}

bool same_blend_group(const Projector& a, const Projector& b) {
  return same_screen_image(a, b) && (a.id == b.id || same_layer(a, b));
}

}  // namespace optique::config
