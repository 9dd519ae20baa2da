#pragma once
// What a node does with its job and its frames: plain, checked values (the
// protocol decoded and checked them). The null renderer and the GL renderer
// (node/gl) implement it.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "clock/clock.h"
#include "protocol/focus.h"
#include "protocol/light_share.h"
#include "protocol/welcome.h"
#include "scene/definition.h"
#include "scene/state.h"
#include "up/schedule.h"
#include "util/result.h"

namespace optique::node {

struct FrameInput {
  std::uint64_t frame_id = 0;
  clock::Nanos simulation_time = 0;
  clock::Nanos present_time = 0;  // predicted, master clock
  clock::Nanos frame_period = 0;
  const scene::SceneState* state = nullptr;
  bool capture = false;                          // also write this frame to the capture folder
  std::optional<protocol::Focus> focus;          // the frame's focal depth and gaze (focus/defocus nodes)
  const protocol::LightShare* lights = nullptr;  // a new share of the lights from this frame on, if any
  // A node that up-converts by interpolation: the scene of a later frame, sent
  // ahead of its turn (at most config::kMostFramesAhead frames on).
  const scene::SceneState* ahead = nullptr;
  std::uint64_t ahead_frame = 0;
};

// What configure()'s warm-up frame took: drawing it (every program and texture
// used once), and reading it back as a captured frame is read (each of its
// images). The master waits that long for the first frame, and a captured
// frame that much longer.
struct WarmUp {
  clock::Nanos frame = 0;    // 0: none was drawn
  clock::Nanos capture = 0;  // 0: not measured
};

// How a frame was drawn: in full, or (a node that up-converts) as a key frame,
// between key frames (and a later key frame drawn ahead with it), or as a key
// frame drawn ahead.
struct Rendered {
  up::FrameKind kind = up::FrameKind::full;
  bool key_ahead = false;
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // The projector, its screen, the viewer and the scene, from the master's welcome.
  [[nodiscard]] virtual Result<void> configure(const protocol::NodeJob& job) = 0;
  // What draws, for the master's log ("llvmpipe (...), headless").
  [[nodiscard]] virtual std::string description() const = 0;
  // How long configure()'s warm-up frame took.
  [[nodiscard]] virtual WarmUp warm_up() const { return {}; }
  // An asset an application loaded, offered while frames go on, its files at
  // `asset.path` (none for a renderer that needs no files), read in two
  // steps: read_asset() on a thread of its own while frames go on (the files
  // read and checked, images decoded; no GL), then add_asset() on the
  // renderer's thread (to the GPU), after which its instances are drawn.
  // Each fails, naming why, when the asset cannot be read or is not what the
  // master offered. (The job's assets are readied by configure().)
  [[nodiscard]] virtual Result<std::shared_ptr<const scene::SceneDefinition>> read_asset(
      const protocol::AssetOffer& asset) const = 0;
  [[nodiscard]] virtual Result<void> add_asset(const protocol::AssetOffer& asset,
                                               const scene::SceneDefinition& read) = 0;
  // Draws the frame into the back buffer; returns when it is ready to show,
  // with how it was drawn.
  virtual Rendered render(const FrameInput& frame) = 0;
  // A frame this node is too far behind to draw: nothing is drawn, but what it
  // carries for later frames (a new share of the lights, the focus, a scene
  // sent ahead) is kept.
  virtual void skip(const FrameInput& frame) { (void)frame; }
  // Shows image `image` of the last rendered frame (swap buffers): 0, or 1 for
  // a projector that shows two images per frame (a stereo one used as mono).
  virtual void present(int image) = 0;
  // Shows black at once (the master is gone and the picture would freeze).
  virtual void show_black() = 0;
};

}  // namespace optique::node
