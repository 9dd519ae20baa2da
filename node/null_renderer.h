#pragma once
// Draws nothing: for runs that measure the cluster's own costs (barrier, clock,
// network) without any rendering in the way.

#include "node/renderer.h"

namespace optique::node {

class NullRenderer final : public Renderer {
 public:
  [[nodiscard]] Result<void> configure(const protocol::NodeJob& job) override;
  [[nodiscard]] std::string description() const override { return "null renderer (draws nothing)"; }
  [[nodiscard]] Result<std::shared_ptr<const scene::SceneDefinition>> read_asset(
      const protocol::AssetOffer&) const override {
    return std::make_shared<const scene::SceneDefinition>();
  }
  [[nodiscard]] Result<void> add_asset(const protocol::AssetOffer&, const scene::SceneDefinition&) override {
    return {};
  }
  Rendered render(const FrameInput& frame) override;
  void present(int image) override;
  void show_black() override {}

  [[nodiscard]] std::uint64_t frames_rendered() const { return rendered_; }
  [[nodiscard]] std::uint64_t frames_presented() const { return presented_; }  // their first images

 private:
  std::uint64_t rendered_ = 0;
  std::uint64_t presented_ = 0;
};

}  // namespace optique::node
