#pragma once
// The node's real renderer: an OpenGL context (headless or a window, as the
// projector's output says), the projector's pipeline (render/projector_pipeline.h),
// shown on present(), and captured on request.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include <spdlog/logger.h>

#include "node/gl/capture_writer.h"
#include "node/renderer.h"
#include "render/gl_context.h"
#include "render/projector_pipeline.h"

namespace optique::node {

class GlRenderer final : public Renderer {
 public:
  // Captures go to `capture_folder`/frame-NNNNNN.{exr,png} (a second image per
  // frame to `capture_folder`/second-image/).
  GlRenderer(spdlog::logger& log, std::string capture_folder);
  ~GlRenderer() override;

  [[nodiscard]] Result<void> configure(const protocol::NodeJob& job) override;
  [[nodiscard]] Result<std::shared_ptr<const scene::SceneDefinition>> read_asset(
      const protocol::AssetOffer& asset) const override;
  [[nodiscard]] Result<void> add_asset(const protocol::AssetOffer& asset, const scene::SceneDefinition& read) override;
  [[nodiscard]] std::string description() const override;
  [[nodiscard]] WarmUp warm_up() const override { return warm_up_; }
  Rendered render(const FrameInput& frame) override;
  void skip(const FrameInput& frame) override;
  void present(int image) override;
  void show_black() override;

 private:
  spdlog::logger& log_;
  std::string capture_folder_;
  std::string configured_for_;    // the job, to skip rebuilding on a rejoin
  std::set<std::string> assets_;  // the ids of the assets the pipeline has
  std::unique_ptr<render::GlContext> context_;
  std::unique_ptr<render::ProjectorPipeline> pipeline_;
  std::optional<CaptureWriter> captures_;
  // The drawn image as a capture takes it.
  struct ReadBack {
    image::FloatImage linear;
    image::ByteImage encoded;  // none when the signal is deeper than 8 bits
    image::WordImage signal;   // only then
  };
  [[nodiscard]] ReadBack read_back() const;
  // What a frame carries for later ones (lights, focus, the scene ahead).
  void take_along(const FrameInput& frame);

  WarmUp warm_up_;
  bool warned_gather_radius_ = false;
  bool gathers_ = false;      // method gather (else the clamp can only be per-field's blur)
  bool deep_signal_ = false;  // the projector takes more than 8 bits: captures are 16-bit PNGs
  // Up-conversion: the scenes the master sent ahead, by frame, until their
  // frame has passed; the ratio last logged.
  std::map<std::uint64_t, scene::SceneState> ahead_;
  std::optional<std::uint64_t> last_frame_;  // frames that go back (a new run) drop what was sent ahead
  int logged_ratio_ = 0;
  // A captured frame on a window: what the window shows is read back when it is presented.
  std::optional<std::uint64_t> read_back_shown_;
};

}  // namespace optique::node
