#pragma once
// A frame's focus, for the focus/defocus pair: the focal depth and where the
// viewer looks. The master computes it per frame; the nodes draw their share.

#include <glm/vec2.hpp>

#include "optique/wire.pb.h"
#include "util/result.h"

namespace optique::protocol {

struct Focus {
  double depth = 0.0;    // metres from the eye along the screen's normal, > 0
  glm::dvec2 gaze{0.0};  // screen metres, in the projector's screen frame

  friend bool operator==(const Focus&, const Focus&) = default;
};

[[nodiscard]] wire::Focus to_wire(const Focus& focus);
// Fails on a depth that is not a finite number > 0, or a gaze that is not finite.
[[nodiscard]] Result<Focus> decode_focus(const wire::Focus& focus);

}  // namespace optique::protocol
