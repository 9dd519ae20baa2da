#include "node/null_renderer.h"

#include <cassert>

namespace optique::node {

Result<void> NullRenderer::configure(const wire::Welcome& welcome) {
  if (welcome.projector().width() == 0 || welcome.projector().height() == 0) {
    return Error{"the welcome names a projector without a resolution"};
  }
  return {};
}

void NullRenderer::render(const FrameInput& frame) {
  assert(frame.state != nullptr);
  (void)frame;
  ++rendered_;
}

void NullRenderer::present() { ++presented_; }

}  // namespace optique::node
