// The master core's part in assets applications load while frames go on
// (master/protocol.h): offered to every node past its hello, served by the
// scene server, and usable by the live scene once every node in the frames
// has readied it, so that no node is ever asked to draw an instance of an
// asset it does not have. A node that joins later gets every asset in its
// welcome and readies them before it is configured.
#include <fmt/format.h>

#include <algorithm>
#include <cassert>

#include "log/escape.h"
#include "master/protocol.h"

namespace optique::master {

Actions MasterProtocol::add_asset(const std::string& id, std::shared_ptr<const scene::LoadedScene> asset) {
  Actions out;
  assert(asset && !asset->manifest.files.empty());
  assert(std::none_of(assets_.begin(), assets_.end(), [&](const LiveAsset& a) { return a.offer.asset == id; }));
  LiveAsset added{protocol::AssetOffer{id, asset->content_sha256, asset->manifest, ""}, asset, false};
  scene_server_.add(id, asset);
  wire::Envelope offer;
  *offer.mutable_asset_offer() = protocol::to_wire(added.offer);
  std::size_t offered = 0;
  for (auto& [peer, session] : sessions_) {
    if (!session.slot || session.phase == Phase::handshake || session.refused) continue;
    out.push_back(Send{peer, offer});
    ++offered;
  }
  out.push_back(
      Log{spdlog::level::info, fmt::format("asset '{}' ({}, {} file(s), {:.1f} MiB) offered to {} node(s)", id,
                                           log::escape_for_log(asset->source), asset->manifest.files.size(),
                                           static_cast<double>(asset->manifest.total_bytes()) / (1 << 20), offered)});
  assets_.push_back(std::move(added));
  check_assets(out);
  return out;
}

std::vector<protocol::AssetOffer> MasterProtocol::asset_offers() const {
  std::vector<protocol::AssetOffer> offers;
  offers.reserve(assets_.size());
  for (const LiveAsset& asset : assets_) offers.push_back(asset.offer);
  return offers;
}

void MasterProtocol::on_asset_ready(Session& session, const wire::AssetReady& ready, Actions& out) {
  const auto asset =
      std::find_if(assets_.begin(), assets_.end(), [&](const LiveAsset& a) { return a.offer.asset == ready.asset(); });
  const std::string node = slot_id(*session.slot);
  if (asset == assets_.end()) {
    // Failed on another node meanwhile: nothing waits for it.
    out.push_back(Log{spdlog::level::debug,
                      fmt::format("'{}' answered for asset '{}', which is not offered", node,
                                  log::escape_for_log(ready.asset().substr(0, scene::kMaxInstanceIdLength)))});
    return;
  }
  if (!ready.problem().empty()) {
    const std::string reason =
        fmt::format("node '{}' cannot draw it: {}", node, log::escape_for_log(ready.problem().substr(0, 1000)));
    out.push_back(Log{spdlog::level::warn, fmt::format("asset '{}' is not used: {}", asset->offer.asset, reason)});
    out.push_back(AssetFailed{asset->offer.asset, reason});
    scene_server_.remove(asset->offer.sha256);
    assets_.erase(asset);
    return;
  }
  session.assets_ready.insert(asset->offer.asset);
  check_assets(out);
}

void MasterProtocol::check_assets(Actions& out) {
  for (LiveAsset& asset : assets_) {
    if (asset.usable) continue;
    const bool everywhere = std::all_of(slots_.begin(), slots_.end(), [&](const Slot& slot) {
      return !up(slot) || sessions_.at(*slot.peer).assets_ready.contains(asset.offer.asset);
    });
    if (!everywhere) continue;
    asset.usable = true;
    out.push_back(Log{spdlog::level::info, fmt::format("asset '{}' is ready on {} node(s) in the frames: usable from "
                                                       "frame {}",
                                                       asset.offer.asset, nodes_up(), next_frame_)});
    out.push_back(AssetUsable{asset.offer.asset, next_frame_, asset.scene->source, asset.offer.sha256,
                              !asset.scene->definition.objects.empty()});
  }
}

}  // namespace optique::master
