// The master's live scene: made with master.api or --replay; its journal
// restored (--record) or replayed (--replay); its session port.

#include <unistd.h>

#include <chrono>
#include <filesystem>

#include "master/app/master.h"
#include "scene_load/installation_scene.h"

namespace optique::master {

Result<void> Master::make_live_scene(RunSettings& run) {
  const config::MasterSettings& settings = options_.config.installation.master;
  const std::string& record = options_.record_path;
  const std::string& replay = options_.replay_path;
  if (!record.empty() && !replay.empty()) {
    return Error{"--record and --replay: a master records a session or replays one, not both at once"};
  }
  if (!record.empty() && !settings.api) {
    return Error{"--record " + record + ": the config has no master.api, so no application can change the scene"};
  }
  if (!settings.api && replay.empty()) return {};

  // For now the one asset is the installation's own scene, by name.
  live_.emplace(LiveScene::of(options_.scene.definition, live_scene_limits(settings.api), settings.frame_rate));
  const std::string& asset = options_.scene.definition.asset_id;
  run.live = &*live_;

  if (!replay.empty()) {
    auto journal = read_journal_file(replay);
    if (!journal) return Error{"--replay: " + journal.error()};
    if (auto assets = load_journal_assets(journal.value()); !assets)
      return Error{"--replay " + replay + ": " + assets.error()};
    auto replaying = JournalReplay::start(journal.value(), *live_);
    if (!replaying) return Error{"--replay " + replay + ": " + replaying.error()};
    journal_replay_.emplace(std::move(replaying).value());
    run.journal_replay = &*journal_replay_;
    log_.info("replaying {}: {} transaction(s) of its last run, over {} instance(s) from the {} run(s) before it",
              replay, journal_replay_->total(), live_->instances().size(), journal.value().runs.size() - 1);
  }

  std::optional<JournalFile> journal_file;
  if (!record.empty()) {
    Journal journal;
    auto file = JournalFile::open(record, journal);
    if (!file) return Error{"--record: " + file.error()};
    if (!journal.torn.empty()) {
      log_.warn("{}: cut away its torn last entry ({}): a write the last master's end cut short, never acknowledged",
                record, journal.torn);
    }
    if (auto assets = load_journal_assets(journal); !assets) return Error{"--record " + record + ": " + assets.error()};
    auto restored = restore(*live_, journal);
    if (!restored) return Error{"--record " + record + ": " + restored.error()};
    if (!journal.runs.empty()) {
      log_.info("restored the live scene from {}: {} transaction(s) of {} run(s), {} instance(s)", record,
                restored.value(), journal.runs.size(), live_->instances().size());
    }
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    if (auto started = file.value().append(
            journal_start(std::chrono::duration_cast<std::chrono::milliseconds>(now).count(), asset));
        !started) {
      return Error{"--record: " + started.error()};
    }
    log_.info("recording the live scene's transactions into {}", record);
    journal_file.emplace(std::move(file).value());
  }
  if (settings.api) {
    // Uploads beside the journal, so that a restart finds them; without one,
    // for this run only.
    const SessionPort::Uploads uploads =
        !record.empty()
            ? SessionPort::Uploads{record + ".assets", false}
            : SessionPort::Uploads{
                  (std::filesystem::temp_directory_path() / ("optique-assets-" + std::to_string(getpid()))).string(),
                  true};
    session_port_.emplace(io_, *settings.api, *live_, std::move(journal_file), options_.run.secret,
                          settings.max_message_bytes, uploads, log_);
  }
  return {};
}

Result<void> Master::load_journal_assets(const Journal& journal) {
  for (const session::JournalAsset& entry : journal.assets) {
    const std::string& id = entry.asset();
    auto loaded = config::load_asset(id, entry.path(), {}, entry.sha256());
    if (!loaded) return Error{"asset '" + id + "': " + loaded.error()};
    live_->add_asset(id, !loaded.value().definition.objects.empty());
    journal_assets_.emplace_back(id, std::make_shared<const scene::LoadedScene>(std::move(loaded).value()));
  }
  if (!journal.assets.empty()) log_.info("loaded {} asset(s) the journal names", journal.assets.size());
  return {};
}

}  // namespace optique::master
