#include "node/null_renderer.h"

#include <cassert>

namespace optique::node {

Result<void> NullRenderer::configure(const protocol::NodeJob&) { return {}; }

Rendered NullRenderer::render(const FrameInput& frame) {
  assert(frame.state != nullptr);
  (void)frame;
  ++rendered_;
  return {};
}

void NullRenderer::present(int image) {
  if (image == 0) ++presented_;
}

}  // namespace optique::node
