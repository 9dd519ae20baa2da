#pragma once
// A node's job, as the master's welcome carries it: its projector, its screen, the
// projectors it blends with, the viewer, the scene (a glTF's files and their
// identity, and how many lights it has), the depth of field's range, the timing,
// and its first share of the lights. Written in the installation's schema (config/to_schema.h) and read
// back on the node by the same parser that checks config files: a welcome that
// would not pass as a config is refused, naming the field.

#include <chrono>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "clock/clock.h"
#include "config/parse.h"
#include "optique/wire.pb.h"
#include "protocol/light_share.h"
#include "scene/manifest.h"
#include "util/result.h"

namespace optique::protocol {

// An asset an application loaded (the scene session's LoadAsset), as the
// master offers it to nodes: its id, its files and their identity.
struct AssetOffer {
  std::string asset;
  std::string sha256;          // the manifest's SHA-256
  scene::SceneManifest files;  // checked, hashing to sha256
  // Where this node reads it from: its copy of the master's files (set by the
  // node once it has them).
  std::string path;
};

struct NodeJob {
  config::ProjectorJob job;
  std::string scene_sha256;          // the glTF's identity (its manifest's SHA-256); empty for built-in scenes
  scene::SceneManifest scene_files;  // checked, and hashing to scene_sha256; none for built-in scenes
  // Where this node reads the glTF from: its copy of the master's files (set by
  // the node once it has them); empty: the installation's path.
  std::string scene_path;
  std::uint32_t light_count = 0;  // the scene's lights: every share names fewer
  clock::Nanos frame_period = 0;
  std::chrono::milliseconds heartbeat{0};
  std::chrono::milliseconds liveness_timeout{0};
  std::optional<LightShare> lights;  // role lights: the share it starts with
  std::vector<AssetOffer> assets;    // loaded by applications: readied before the node is configured
};

// The welcome for projector `projector` of `installation`, whose scene is made
// of `scene_files` (none: a built-in scene).
[[nodiscard]] wire::Welcome encode_welcome(const config::Installation& installation, std::size_t projector,
                                           const scene::SceneManifest& scene_files, std::uint32_t light_count,
                                           clock::Nanos frame_period, const LightShare* share,
                                           std::span<const AssetOffer> assets = {});

// The job a welcome gives the node `projector_id`; fails, naming what is wrong,
// for a job that does not parse, a timing out of range, a share of the lights
// that names lights the scene does not have, or a scene manifest that does not
// pass scene::check_manifest or does not hash to the scene's identity.
[[nodiscard]] Result<NodeJob> decode_welcome(const wire::Welcome& welcome, std::string_view projector_id);

[[nodiscard]] wire::AssetOffer to_wire(const AssetOffer& offer);
// Fails, naming what is wrong, for an id that is not one (scene::is_instance_id),
// a manifest that does not pass scene::check_manifest or does not hash to
// its SHA-256, or one with no files.
[[nodiscard]] Result<AssetOffer> decode_asset_offer(const wire::AssetOffer& offer);

[[nodiscard]] wire::LightShare to_wire(const LightShare& share);
[[nodiscard]] wire::SceneManifest to_wire(const scene::SceneManifest& manifest);
// Fails when an index is not below `light_count` (the scene's lights) plus
// scene::kMaxAddedLights (those applications may add), or indices repeat or
// descend.
[[nodiscard]] Result<LightShare> decode_light_share(const wire::LightShare& share, std::uint32_t light_count);

}  // namespace optique::protocol
