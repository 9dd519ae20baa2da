// The node core's part in assets an application loads while frames go on
// (node/protocol.h): each offer is queued, and once this node is in the
// frames they are readied one at a time — the files found in the cache or
// fetched from the master beside the frames (as the scene's are while a node
// sets up), then given to the renderer — and the master told of each, ready
// or not. An asset that cannot be readied costs that asset, never the node.
// Offers are not kept over a lost connection: the next welcome names every
// asset, and the node readies them before it is configured.
#include <fmt/format.h>

#include <algorithm>

#include "node/protocol.h"

namespace optique::node {

void NodeProtocol::on_asset_offer(const wire::AssetOffer& offer, Actions& out) {
  auto asset = protocol::decode_asset_offer(offer);
  if (!asset) {
    out.push_back(Close{"an asset offer the master cannot have meant: " + asset.error()});
    return;
  }
  const std::string& id = asset.value().asset;
  const auto named = [&](const protocol::AssetOffer& a) { return a.asset == id; };
  if (std::any_of(offers_.begin(), offers_.end(), named) || (readying_ && readying_->asset == id) ||
      offers_.size() >= scene::kMaxAssets) {
    out.push_back(Close{"the master offered asset '" + id + "' twice, or more assets than it may"});
    return;
  }
  // One readied here before: it failed on another node and was loaded again
  // (perhaps other content): readied again, in its place.
  std::erase_if(job_->assets, named);
  offers_.push_back(std::move(asset).value());
  ready_next(out);
}

void NodeProtocol::ready_next(Actions& out) {
  if (phase_ != Phase::joined || readying_ || offers_.empty()) return;
  readying_ = std::move(offers_.front());
  offers_.pop_front();
  if (!settings_.needs_scene_files) {
    asset_done("", out);  // nothing drawn, nothing to fetch
    return;
  }
  log(out, spdlog::level::info,
      fmt::format("readying the asset '{}' the master offered ({} file(s), {:.1f} MiB)", readying_->asset,
                  readying_->files.files.size(), static_cast<double>(readying_->files.total_bytes()) / (1 << 20)));
  prepare(FetchTarget{"the asset '" + readying_->asset + "'", "", readying_->files, readying_->sha256, &readying_->path,
                      true},
          out);
}

void NodeProtocol::on_asset_loaded(const AssetLoaded& answer, Actions& out) {
  if (phase_ != Phase::joined || !readying_ || readying_->asset != answer.asset) return;  // the connection went
  asset_done(answer.result ? "" : answer.result.error(), out);
}

void NodeProtocol::asset_done(const std::string& problem, Actions& out) {
  if (!readying_) return;
  if (problem.empty()) {
    // Known from now on, as the welcome's are: a rejoin keeps it.
    job_->assets.push_back(*readying_);
  } else {
    log(out, spdlog::level::warn, "the asset '" + readying_->asset + "' cannot be drawn here: " + problem);
  }
  wire::Envelope ready;
  ready.mutable_asset_ready()->set_asset(readying_->asset);
  ready.mutable_asset_ready()->set_problem(problem);
  out.push_back(Send{std::move(ready)});
  readying_.reset();
  ready_next(out);
}

}  // namespace optique::node
