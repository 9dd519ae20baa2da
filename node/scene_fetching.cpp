// The node core's part in getting the scene's files (node/protocol.h): found
// in the cache, waited for while another node of this host fetches them, or
// fetched from the master chunk by chunk into a copy the shell's cache writes.
#include <fmt/format.h>

#include <algorithm>

#include "node/protocol.h"

namespace optique::node {

// The cache cannot hold the scene (no room, no permission): not something a
// retry cures.
void NodeProtocol::cache_failed(const std::string& error, Actions& out) {
  if (copy_unfinished_) out.push_back(AbandonScene{});
  copy_unfinished_ = false;
  if (target_ && target_->in_frames) {
    // One asset cannot be kept: the frames go on without it.
    const std::string name = target_->name;
    target_.reset();
    fetch_.reset();
    out.push_back(CancelDeadline{});
    asset_done("cannot keep " + name + " here: " + error, out);
    return;
  }
  const bool scene = !target_ || target_->path == &job_->scene_path;
  stop(kExitRefused, "cannot keep " + (scene ? std::string("the master's scene") : target_->name) + " here: " + error,
       out);
}

bool NodeProtocol::fetch_at(Phase stage) const {
  if (!target_ || target_->stage != stage) return false;
  return target_->in_frames ? phase_ == Phase::joined : phase_ == stage;
}

void NodeProtocol::set_fetch_stage(Phase stage) {
  target_->stage = stage;
  if (!target_->in_frames) phase_ = stage;
}

void NodeProtocol::prepare_next(Actions& out) {
  if (settings_.needs_scene_files) {
    if (!job_->scene_files.files.empty() && job_->scene_path.empty()) {
      prepare(FetchTarget{"the scene", " " + job_->job.installation.scene.gltf, job_->scene_files, job_->scene_sha256,
                          &job_->scene_path},
              out);
      return;
    }
    for (protocol::AssetOffer& asset : job_->assets) {
      if (asset.path.empty()) {
        prepare(FetchTarget{"the asset '" + asset.asset + "'", "", asset.files, asset.sha256, &asset.path}, out);
        return;
      }
    }
  }
  configure(out);
}

void NodeProtocol::prepare(FetchTarget target, Actions& out) {
  const std::uint64_t bytes = target.files.total_bytes();
  if (bytes > settings_.most_scene_bytes) {
    const std::string problem = fmt::format(
        "{}{} is {:.1f} MiB, more than the {:.1f} MiB this node takes (--max-scene-mb)", target.name, target.detail,
        static_cast<double>(bytes) / (1 << 20), static_cast<double>(settings_.most_scene_bytes) / (1 << 20));
    if (target.in_frames) {
      asset_done(problem, out);
    } else {
      stop(kExitRefused, "the master's " + problem.substr(4), out);
    }
    return;
  }
  // In the frames no other node's copy is waited for: the master hears of
  // waits only while a node sets up.
  const bool wait_for_others = !target.in_frames;
  out.push_back(PrepareScene{target.files, target.sha256, wait_for_others});
  target_ = std::move(target);
  set_fetch_stage(Phase::preparing_scene);
}

void NodeProtocol::fetched(const std::string& path, Actions& out) {
  *target_->path = path;
  const bool in_frames = target_->in_frames;
  target_.reset();
  if (in_frames) {
    out.push_back(CancelDeadline{});
    out.push_back(ReadyAsset{*readying_});
    return;
  }
  prepare_next(out);
}

void NodeProtocol::on_scene_found(const SceneFound& answer, Actions& out) {
  if (!fetch_at(Phase::preparing_scene)) return;
  log(out, spdlog::level::info,
      target_->name + " (" + target_->sha256.substr(0, 12) + "…) is here: " + answer.gltf_path +
          (waiting_ ? ", fetched by another node of this host" : ""));
  waiting_.reset();
  fetched(answer.gltf_path, out);
}

void NodeProtocol::on_scene_fetched_elsewhere(const SceneFetchedElsewhere& answer, clock::Nanos now, Actions& out) {
  if (!fetch_at(Phase::preparing_scene) || target_->in_frames) return;
  const std::uint64_t total = target_->files.total_bytes();
  const std::uint64_t bytes_there = std::min(answer.bytes_there, total);
  const auto mib = [](std::uint64_t bytes) { return static_cast<double>(bytes) / (1 << 20); };
  if (!waiting_) {
    waiting_ = SceneWaiting{now, now, std::nullopt, bytes_there};
    log(out, spdlog::level::info,
        fmt::format("another node of this host is fetching {}{} into this cache ({:.1f} of {:.1f} MiB "
                    "there): waiting for its copy",
                    target_->name, target_->detail, mib(bytes_there), mib(total)));
  } else if (bytes_there > waiting_->bytes) {
    waiting_->bytes = bytes_there;
    waiting_->grew_at = now;
  }
  if (now - waiting_->grew_at >= kSceneStall.count() * clock::kNanosPerMilli) {
    log(out, spdlog::level::warn,
        fmt::format("the copy of {} another node of this host is fetching has not grown for {} s "
                    "({:.1f} of {:.1f} MiB there): fetching {} from the master",
                    target_->name, kSceneStall.count() / 1000, mib(waiting_->bytes), mib(total), target_->name));
    waiting_.reset();
    out.push_back(PrepareScene{target_->files, target_->sha256, false});
    return;
  }
  if (!waiting_->told_at || now - *waiting_->told_at >= kSceneWaitWord.count() * clock::kNanosPerMilli) {
    waiting_->told_at = now;
    wire::Envelope wait;
    wait.mutable_scene_wait()->set_scene_sha256(target_->sha256);
    wait.mutable_scene_wait()->set_bytes_there(waiting_->bytes);
    out.push_back(Send{std::move(wait)});
  }
  // Past the stall, in case the cache stops answering: the connection goes.
  out.push_back(SetDeadline{kSceneStall + 2 * kSceneWaitWord,
                            "waited " + std::to_string((kSceneStall + 2 * kSceneWaitWord).count() / 1000) +
                                " s for another node's copy of " + target_->name});
  out.push_back(RecheckScene{kSceneRecheck});
}

void NodeProtocol::on_scene_recheck_due(Actions& out) {
  if (!fetch_at(Phase::preparing_scene) || !waiting_) return;
  out.push_back(PrepareScene{target_->files, target_->sha256});
}

void NodeProtocol::on_scene_copy_started(const SceneCopyStarted& answer, clock::Nanos now, Actions& out) {
  const Result<protocol::SceneFetch::Present>& started = answer.started;
  if (!fetch_at(Phase::preparing_scene)) return;
  if (!started) {
    cache_failed(started.error(), out);
    return;
  }
  copy_unfinished_ = true;
  waiting_.reset();
  fetch_.emplace(target_->files, target_->sha256, started.value());
  fetch_started_ = now;
  fetch_had_bytes_ = fetch_->bytes_stored();
  fetch_quarters_logged_ = 0;
  set_fetch_stage(Phase::fetching_scene);
  const double total = static_cast<double>(target_->files.total_bytes()) / (1 << 20);
  log(out, spdlog::level::info,
      fetch_->bytes_stored() == 0
          ? fmt::format("fetching {}{} from the master: {} file(s), {:.1f} MiB", target_->name, target_->detail,
                        target_->files.files.size(), total)
          : fmt::format("fetching the rest of {}{} from the master: {:.1f} of {:.1f} MiB were here already",
                        target_->name, target_->detail, static_cast<double>(fetch_->bytes_stored()) / (1 << 20),
                        total));
  out.push_back(SetDeadline{kSceneStall, "no part of " + target_->name + " from the master for " +
                                             std::to_string(kSceneStall.count() / 1000) + " s"});
  for (wire::Envelope& request : fetch_->requests()) out.push_back(Send{std::move(request)});
  if (fetch_->done()) out.push_back(FinishScene{});  // only empty files
}

void NodeProtocol::on_scene_chunk(const wire::SceneChunk& chunk, Actions& out) {
  const protocol::SceneFetch::Verdict verdict = fetch_->take(chunk);
  switch (verdict.kind) {
    case protocol::SceneFetch::Verdict::Kind::fail:
      out.push_back(Close{target_->name + " from the master: " + verdict.problem});
      return;
    case protocol::SceneFetch::Verdict::Kind::ask_again:
      log(out, spdlog::level::warn, target_->name + " from the master: " + verdict.problem + "; asking for it again");
      break;
    case protocol::SceneFetch::Verdict::Kind::store:
      out.push_back(StoreSceneChunk{verdict.file, verdict.offset, chunk.data()});
      break;
  }
  out.push_back(SetDeadline{kSceneStall, "no part of " + target_->name + " from the master for " +
                                             std::to_string(kSceneStall.count() / 1000) + " s"});
  const std::uint64_t total = fetch_->manifest().total_bytes();
  const int quarters = total == 0 ? 4 : static_cast<int>(4 * fetch_->bytes_stored() / total);
  if (quarters > fetch_quarters_logged_ && quarters < 4 && total >= protocol::kSceneProgressBytes) {
    fetch_quarters_logged_ = quarters;
    log(out, spdlog::level::info, fmt::format("fetching {}: {} %", target_->name, 25 * quarters));
  }
  if (fetch_->done()) {
    out.push_back(FinishScene{});
    return;
  }
  for (wire::Envelope& request : fetch_->requests()) out.push_back(Send{std::move(request)});
}

void NodeProtocol::on_scene_store_failed(const SceneStoreFailed& answer, Actions& out) {
  if (!fetch_at(Phase::fetching_scene)) return;
  cache_failed(answer.error, out);
}

void NodeProtocol::on_scene_copy_finished(const SceneCopyFinished& answer, clock::Nanos now, Actions& out) {
  const Result<std::string>& gltf_path = answer.gltf_path;
  if (!fetch_at(Phase::fetching_scene)) return;
  if (!gltf_path) {
    cache_failed(gltf_path.error(), out);
    return;
  }
  copy_unfinished_ = false;
  // From the first request to the copy in place.
  log(out, spdlog::level::info,
      fmt::format("fetched {}: {}{}", target_->name,
                  protocol::transfer_text(fetch_->manifest().total_bytes() - fetch_had_bytes_, now - fetch_started_),
                  fetch_->chunks_asked_again() > 0
                      ? fmt::format(", {} chunk(s) asked for again", fetch_->chunks_asked_again())
                      : ""));
  fetch_.reset();
  fetched(gltf_path.value(), out);
}

}  // namespace optique::node
