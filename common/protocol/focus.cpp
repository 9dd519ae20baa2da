#include "protocol/focus.h"

#include <cmath>

#include "util/number_text.h"

namespace optique::protocol {

wire::Focus to_wire(const Focus& focus) {
  wire::Focus out;
  out.set_depth(focus.depth);
  out.set_gaze_x(focus.gaze.x);
  out.set_gaze_y(focus.gaze.y);
  return out;
}

Result<Focus> decode_focus(const wire::Focus& focus) {
  if (!std::isfinite(focus.depth()) || focus.depth() <= 0.0) {
    return Error{"focus depth " + util::number_text(focus.depth()) + " is not a finite number of metres > 0"};
  }
  if (!std::isfinite(focus.gaze_x()) || !std::isfinite(focus.gaze_y())) {
    return Error{"the gaze point [" + util::number_text(focus.gaze_x()) + ", " + util::number_text(focus.gaze_y()) +
                 "] is not finite"};
  }
  return Focus{focus.depth(), {focus.gaze_x(), focus.gaze_y()}};
}

}  // namespace optique::protocol
