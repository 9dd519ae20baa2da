#pragma once
// A transaction of edits to the live scene, built by name: what the master
// applies whole in one frame, or not at all (proto/optique/session.proto).

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "optique/session.pb.h"

namespace optique::client {

// A placement; what is left out (nullopt) keeps its value.
struct Placement {
  std::optional<std::array<double, 3>> position;  // metres
  std::optional<std::array<double, 4>> rotation;  // quaternion w, x, y, z (any length but 0)
  std::optional<std::array<double, 3>> scale;
};

class Transaction {
 public:
  // A new instance of `asset` under `parent` (empty: the world).
  Transaction& create(const std::string& instance, const std::string& asset, const Placement& placement = {},
                      const std::string& parent = {}, bool hidden = false);
  Transaction& move(const std::string& instance, const Placement& placement);
  Transaction& reparent(const std::string& instance, const std::string& parent);
  Transaction& show(const std::string& instance, bool visible = true);
  Transaction& hide(const std::string& instance) { return show(instance, false); }
  // Factors on the asset's materials: base colour r, g, b, a in [0, 1]; emissive r, g, b ≥ 0.
  Transaction& tint(const std::string& instance, const std::array<double, 4>& base_color);
  Transaction& glow(const std::string& instance, const std::array<double, 3>& emissive);
  // The instance and everything under it.
  Transaction& remove(const std::string& instance);
  // Where the installation is in the world (world ← installation): the viewer
  // travels. A uniform scale only ([s, s, s]).
  Transaction& navigate(const Placement& placement);
  // One of the scene's point lights, by its index, on or off.
  Transaction& switch_light(std::uint32_t light, bool on);
  // Adds a point light (index from the scene's light count on), or changes
  // one added before: where it is (world metres; needed to add it), its
  // linear colour, its intensity. What is left out keeps its value.
  Transaction& point_light(std::uint32_t light, std::optional<std::array<double, 3>> position,
                           std::optional<std::array<double, 3>> colour = std::nullopt,
                           std::optional<double> intensity = std::nullopt);
  Transaction& remove_point_light(std::uint32_t light);
  // The instance's own clock for its asset's animations: played or paused
  // (nullopt: as it was), sought to `seek` seconds (nullopt: where it is).
  Transaction& animate(const std::string& instance, std::optional<bool> playing,
                       std::optional<double> seek = std::nullopt);

  [[nodiscard]] const session::Transaction& message() const { return message_; }
  [[nodiscard]] bool empty() const { return message_.edits_size() == 0; }

 private:
  session::Transaction message_;
};

}  // namespace optique::client
