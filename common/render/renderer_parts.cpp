#include "render/renderer_parts.h"

#include <algorithm>

namespace optique::render {

void RendererParts::draw(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms, Objects which,
                         const Motion* motion) {
  scene.draw(state, view, terms, linear.format().width, linear.format().height, which, motion);
}

void RendererParts::draw_linear(const scene::SceneState& state, const Viewpoint& view, const LightTerms& terms) {
  rendered_is_linear();
  linear.begin(scene.background());
  draw(state, view, terms);
  linear.resolve();
}

void RendererParts::draw_fields(const scene::SceneState& state, std::span<const FieldPass> passes,
                                const LightTerms& terms, bool still_once_allowed) {
  rendered_is_linear();
  linear.begin(scene.background());
  // Seen from one place in every field (the viewer does not move), what does not
  // move looks the same in each: it is drawn once, in every channel, and each
  // field draws only the moving objects over it, on the still objects' depth.
  const bool one_view = std::all_of(passes.begin(), passes.end(),
                                    [&](const FieldPass& p) { return p.view.same_place(passes.front().view); });
  // With nothing still, keeping depth aside would only cost (measured: 0.86× the
  // frame time without it on the moving square).
  const bool still_once = still_once_allowed && scene.anything_still() && !passes.empty() && one_view;
  if (still_once) {
    draw(state, passes.front().view, terms, Objects::still);
    linear.keep_still_depth();
  }
  for (const FieldPass& pass : passes) {
    // Each pass sees the scene at its moment: depth starts over (from the still
    // objects'), the other passes' colours stay. Alpha keeps the clear's 1.
    if (still_once) {
      linear.bring_back_still_depth();
    } else {
      glClear(GL_DEPTH_BUFFER_BIT);
    }
    glColorMask(pass.red, pass.green, pass.blue, GL_FALSE);
    draw(state, pass.view, terms, still_once ? Objects::moving : Objects::all);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }
  linear.resolve();
}

}  // namespace optique::render
