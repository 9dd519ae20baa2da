#include "master/session/journal.h"

#include "log/escape.h"
#include "util/read_file.h"

namespace optique::master {
namespace {

std::string framed(const session::JournalEntry& entry) {
  const std::string body = entry.SerializeAsString();
  const auto length = static_cast<std::uint32_t>(body.size());
  std::string out;
  out.reserve(4 + body.size());
  for (int shift = 0; shift < 32; shift += 8) out.push_back(static_cast<char>((length >> shift) & 0xffu));
  return out + body;
}

std::string where(std::size_t run, std::size_t index, const session::JournalTransaction& t) {
  return "run " + std::to_string(run + 1) + ", transaction " + std::to_string(index + 1) + " (frame " +
         std::to_string(t.frame()) + ", from '" + log::escape_for_log(t.application()) + "')";
}

std::string refused_text(const Refusal& refusal) { return refusal.field + ": " + refusal.reason; }

}  // namespace

std::string journal_start(std::int64_t unix_ms, const std::string& scene_asset) {
  session::JournalEntry entry;
  entry.mutable_start()->set_unix_ms(unix_ms);
  entry.mutable_start()->set_scene_asset(scene_asset);
  return framed(entry);
}

std::string journal_transaction(std::uint64_t frame, const std::string& application,
                                const session::Transaction& transaction) {
  session::JournalEntry entry;
  auto& t = *entry.mutable_transaction();
  t.set_frame(frame);
  t.set_application(application);
  *t.mutable_transaction() = transaction;
  return framed(entry);
}

std::string journal_asset(std::uint64_t frame, const std::string& asset, const std::string& path,
                          const std::string& sha256) {
  session::JournalEntry entry;
  auto& a = *entry.mutable_asset();
  a.set_frame(frame);
  a.set_asset(asset);
  a.set_path(path);
  a.set_sha256(sha256);
  return framed(entry);
}

Result<Journal> read_journal(std::string_view bytes) {
  Journal journal;
  if (bytes.size() < kJournalMagic.size() && kJournalMagic.starts_with(bytes)) {
    if (!bytes.empty()) journal.torn = "the journal's first line, cut short";
    return journal;
  }
  if (!bytes.starts_with(kJournalMagic)) {
    return Error{"does not begin with \"optique journal 1\": not a journal (nothing in it was read or changed)"};
  }
  std::size_t at = kJournalMagic.size();
  journal.whole_bytes = at;
  for (std::size_t index = 0; at < bytes.size(); ++index) {
    const std::string entry_at = "entry " + std::to_string(index + 1) + " at byte " + std::to_string(at);
    if (bytes.size() - at < 4) {
      journal.torn = entry_at + ": " + std::to_string(bytes.size() - at) + " bytes, not a whole length";
      break;
    }
    std::uint32_t length = 0;
    for (int i = 0; i < 4; ++i)
      length |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[at + i])) << (8 * i);
    if (length > kMaxJournalEntryBytes) {
      return Error{entry_at + ": says it is " + std::to_string(length) + " bytes long; no entry is over " +
                   std::to_string(kMaxJournalEntryBytes) + " (is this a journal?)"};
    }
    if (bytes.size() - at - 4 < length) {
      journal.torn =
          entry_at + ": " + std::to_string(bytes.size() - at - 4) + " of its " + std::to_string(length) + " bytes";
      break;
    }
    session::JournalEntry entry;
    if (!entry.ParseFromArray(bytes.data() + at + 4, static_cast<int>(length))) {
      return Error{entry_at + ": is not a journal entry (is this a journal?)"};
    }
    switch (entry.entry_case()) {
      case session::JournalEntry::kStart:
        journal.runs.push_back({entry.start(), {}});
        break;
      case session::JournalEntry::kTransaction: {
        if (journal.runs.empty()) return Error{entry_at + ": a transaction before the journal's first start"};
        auto& transactions = journal.runs.back().transactions;
        if (!transactions.empty() && entry.transaction().frame() < transactions.back().frame()) {
          return Error{entry_at + ": its frame " + std::to_string(entry.transaction().frame()) +
                       " is before the frame of the transaction before it (" +
                       std::to_string(transactions.back().frame()) + ")"};
        }
        transactions.push_back(std::move(*entry.mutable_transaction()));
        break;
      }
      case session::JournalEntry::kAsset:
        if (journal.runs.empty()) return Error{entry_at + ": an asset before the journal's first start"};
        if (!scene::is_instance_id(entry.asset().asset())) return Error{entry_at + ": an asset without an id"};
        journal.assets.push_back(std::move(*entry.mutable_asset()));
        break;
      case session::JournalEntry::ENTRY_NOT_SET:
        return Error{entry_at + ": an entry of a kind this master does not know"};
    }
    at += 4 + length;
    journal.whole_bytes = at;
  }
  return journal;
}

Result<Journal> read_journal_file(const std::string& path) {
  auto bytes = util::read_file(path, "journal");
  if (!bytes) return Error{bytes.error()};
  auto journal = read_journal(bytes.value());
  if (!journal) return Error{path + ": " + journal.error()};
  return journal;
}

namespace {

// Applies runs [0, runs) of `journal`.
Result<std::size_t> restore_runs(LiveScene& live, const Journal& journal, std::size_t runs) {
  std::size_t applied = 0;
  for (std::size_t r = 0; r < runs; ++r) {
    const auto& transactions = journal.runs[r].transactions;
    std::uint64_t last = 0;
    for (std::size_t i = 0; i < transactions.size(); ++i) {
      live.begin_frame();
      if (auto refused = live.apply(transactions[i].transaction(), transactions[i].frame())) {
        return Error{where(r, i, transactions[i]) + " was refused: " + refused_text(*refused) +
                     "; the journal was written for another installation"};
      }
      last = transactions[i].frame();
      ++applied;
    }
    // Each run counts its frames from 0.
    live.begin_run(last);
  }
  return applied;
}

}  // namespace

Result<std::size_t> restore(LiveScene& live, const Journal& journal) {
  return restore_runs(live, journal, journal.runs.size());
}

Result<JournalReplay> JournalReplay::start(const Journal& journal, LiveScene& live) {
  JournalReplay replay;
  if (journal.runs.empty()) return replay;
  auto restored = restore_runs(live, journal, journal.runs.size() - 1);
  if (!restored) return Error{restored.error()};
  replay.transactions_ = journal.runs.back().transactions;
  return replay;
}

std::vector<std::string> JournalReplay::apply_due(LiveScene& live, std::uint64_t frame) {
  std::vector<std::string> problems;
  for (; next_ < transactions_.size() && transactions_[next_].frame() <= frame; ++next_) {
    if (auto refused = live.apply(transactions_[next_].transaction(), transactions_[next_].frame())) {
      problems.push_back("replaying the journal: transaction " + std::to_string(next_ + 1) + " (frame " +
                         std::to_string(transactions_[next_].frame()) + ") was refused: " + refused_text(*refused));
    }
  }
  return problems;
}

Result<void> replay_into(const Journal& journal, const scene::SceneDefinition& scene, LiveSceneLimits limits,
                         double frame_rate, std::uint64_t frame, const std::set<std::string>& animated,
                         scene::SceneState& state) {
  LiveScene live = LiveScene::of(scene, limits, frame_rate);
  for (const session::JournalAsset& asset : journal.assets)
    live.add_asset(asset.asset(), animated.contains(asset.asset()));
  auto replay = JournalReplay::start(journal, live);
  if (!replay) return Error{replay.error()};
  const std::vector<std::string> problems = replay.value().apply_due(live, frame);
  if (!problems.empty()) return Error{problems.front()};
  put_live(live, frame, state);
  return {};
}

}  // namespace optique::master
