#include "protocol/welcome.h"

#include "config/to_schema.h"
#include "scene/state.h"

namespace optique::protocol {
namespace {

// The job part of a welcome as one installation, for config::parse_job: its
// screen, its blend group as the projectors, the viewer, scene and depth of field.
schema::Installation job_of(const wire::Welcome& welcome) {
  schema::Installation job;
  *job.add_screens() = welcome.screen();
  for (const schema::Projector& member : welcome.blend_group()) *job.add_projectors() = member;
  *job.mutable_viewer() = welcome.viewer();
  *job.mutable_scene() = welcome.scene();
  if (welcome.has_depth_of_field()) *job.mutable_depth_of_field() = welcome.depth_of_field();
  return job;
}

// A welcome's manifest, checked for shape (any scene's limits: each node holds
// the size to its own afterwards) and for the scene's identity.
Result<scene::SceneManifest> decode_scene_manifest(const wire::SceneManifest& wire, const std::string& sha256) {
  scene::SceneManifest manifest;
  manifest.chunk_bytes = wire.chunk_bytes();
  for (const wire::SceneFile& file : wire.files()) {
    manifest.files.push_back({file.path(), file.size(), file.sha256(), file.chunk_sha256()});
  }
  if (auto checked = scene::check_manifest(manifest, scene::kLargestScene); !checked) {
    return Error{checked.error()};
  }
  if (scene::manifest_sha256(manifest) != sha256) {
    return Error{"the scene's manifest does not hash to its SHA-256 (" + sha256.substr(0, 64) + ")"};
  }
  return manifest;
}

// Longer than any sane setting, short enough that doubling it cannot overflow.
constexpr clock::Nanos kLongestPeriod = 10 * clock::kNanosPerSecond;
constexpr std::uint32_t kLongestMs = 24 * 3600 * 1000;

}  // namespace

wire::Welcome encode_welcome(const config::Installation& installation, std::size_t projector,
                             const scene::SceneManifest& scene_files, std::uint32_t light_count,
                             clock::Nanos frame_period, const LightShare* share, std::span<const AssetOffer> assets) {
  const config::ProjectorJob job = config::job_for(installation, projector);
  const config::Installation& part = job.installation;
  wire::Welcome welcome;
  *welcome.mutable_projector() = config::to_schema(job.self(), part.screens);
  *welcome.mutable_screen() = config::to_schema(job.screen());
  for (const config::Projector& member : part.projectors)
    *welcome.add_blend_group() = config::to_schema(member, part.screens);
  *welcome.mutable_viewer() = config::to_schema(part.viewer);
  *welcome.mutable_scene() = config::to_schema(part.scene);
  if (part.depth_of_field) *welcome.mutable_depth_of_field() = config::to_schema(*part.depth_of_field, part.screens);
  if (!scene_files.files.empty()) {
    welcome.set_scene_sha256(scene::manifest_sha256(scene_files));
    *welcome.mutable_scene_files() = to_wire(scene_files);
  }
  welcome.set_light_count(light_count);
  for (const AssetOffer& asset : assets) *welcome.add_assets() = to_wire(asset);
  if (share != nullptr) *welcome.mutable_lights() = to_wire(*share);
  welcome.set_frame_period_ns(frame_period);
  welcome.set_heartbeat_ms(static_cast<std::uint32_t>(installation.master.heartbeat.count()));
  welcome.set_liveness_timeout_ms(static_cast<std::uint32_t>(installation.master.liveness_timeout.count()));
  return welcome;
}

Result<NodeJob> decode_welcome(const wire::Welcome& welcome, std::string_view projector_id) {
  NodeJob node;
  if (welcome.frame_period_ns() <= 0 || welcome.frame_period_ns() > kLongestPeriod) {
    return Error{"welcome: frame_period_ns " + std::to_string(welcome.frame_period_ns()) + " is not in (0, 10 s]"};
  }
  if (welcome.heartbeat_ms() == 0 || welcome.heartbeat_ms() > kLongestMs || welcome.liveness_timeout_ms() == 0 ||
      welcome.liveness_timeout_ms() > kLongestMs) {
    return Error{"welcome: heartbeat_ms " + std::to_string(welcome.heartbeat_ms()) + " and liveness_timeout_ms " +
                 std::to_string(welcome.liveness_timeout_ms()) + " must be in [1, 86400000]"};
  }
  if (welcome.projector().id() != projector_id) {
    return Error{"welcome: it is for projector '" + welcome.projector().id() + "', this node drives '" +
                 std::string(projector_id) + "'"};
  }
  schema::Installation job = job_of(welcome);
  // A master that sends no blend group: this projector alone.
  if (job.projectors().empty()) *job.add_projectors() = welcome.projector();
  auto parsed = config::parse_job(job, projector_id, "welcome");
  if (!parsed) return Error{parsed.error()};
  node.job = std::move(parsed).value();
  if (welcome.scene_files().files_size() > 0 || !welcome.scene_sha256().empty()) {
    auto files = decode_scene_manifest(welcome.scene_files(), welcome.scene_sha256());
    if (!files) return Error{"welcome: scene_files: " + files.error()};
    node.scene_files = std::move(files).value();
    node.scene_sha256 = welcome.scene_sha256();
  }
  if (static_cast<std::size_t>(welcome.assets_size()) > scene::kMaxAssets) {
    return Error{"welcome: assets: " + std::to_string(welcome.assets_size()) + " of them, at most " +
                 std::to_string(scene::kMaxAssets)};
  }
  for (int i = 0; i < welcome.assets_size(); ++i) {
    auto asset = decode_asset_offer(welcome.assets(i));
    if (!asset) return Error{"welcome: assets[" + std::to_string(i) + "]: " + asset.error()};
    node.assets.push_back(std::move(asset).value());
  }
  node.light_count = welcome.light_count();
  node.frame_period = welcome.frame_period_ns();
  node.heartbeat = std::chrono::milliseconds(welcome.heartbeat_ms());
  node.liveness_timeout = std::chrono::milliseconds(welcome.liveness_timeout_ms());
  if (node.job.self().content.role == config::ContentRole::lights) {
    auto share = decode_light_share(welcome.lights(), node.light_count);
    if (!share) return Error{"welcome: lights: " + share.error()};
    node.lights = std::move(share).value();
  }
  return node;
}

wire::AssetOffer to_wire(const AssetOffer& offer) {
  wire::AssetOffer out;
  out.set_asset(offer.asset);
  out.set_scene_sha256(offer.sha256);
  *out.mutable_files() = to_wire(offer.files);
  return out;
}

Result<AssetOffer> decode_asset_offer(const wire::AssetOffer& offer) {
  if (!scene::is_instance_id(offer.asset())) {
    return Error{"asset: not an id (1 to 64 letters, digits, '-', '_' or '.')"};
  }
  if (offer.files().files_size() == 0) return Error{"asset '" + offer.asset() + "': files: none"};
  auto files = decode_scene_manifest(offer.files(), offer.scene_sha256());
  if (!files) return Error{"asset '" + offer.asset() + "': files: " + files.error()};
  return AssetOffer{offer.asset(), offer.scene_sha256(), std::move(files).value(), ""};
}

wire::LightShare to_wire(const LightShare& share) {
  wire::LightShare out;
  out.mutable_lights()->Add(share.lights.begin(), share.lights.end());
  out.set_ambient(share.ambient);
  return out;
}

wire::SceneManifest to_wire(const scene::SceneManifest& manifest) {
  wire::SceneManifest out;
  out.set_chunk_bytes(manifest.chunk_bytes);
  for (const scene::SceneFile& file : manifest.files) {
    wire::SceneFile& entry = *out.add_files();
    entry.set_path(file.path);
    entry.set_size(file.size);
    entry.set_sha256(file.sha256);
    entry.set_chunk_sha256(file.chunk_sha256);
  }
  return out;
}

Result<LightShare> decode_light_share(const wire::LightShare& share, std::uint32_t light_count) {
  LightShare out;
  out.ambient = share.ambient();
  for (int i = 0; i < share.lights_size(); ++i) {
    const std::uint32_t light = share.lights(i);
    // The scene's own lights, and those applications may add after them.
    if (light >= std::uint64_t{light_count} + scene::kMaxAddedLights) {
      return Error{"light " + std::to_string(light) + " does not exist (the scene has " + std::to_string(light_count) +
                   ", and at most " + std::to_string(scene::kMaxAddedLights) + " may be added)"};
    }
    if (i > 0 && light <= share.lights(i - 1)) {
      return Error{"lights must ascend, each once (" + std::to_string(light) + " after " +
                   std::to_string(share.lights(i - 1)) + ")"};
    }
    out.lights.push_back(light);
  }
  return out;
}

}  // namespace optique::protocol
