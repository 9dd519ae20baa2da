#pragma once
// The journal of the live scene (the master's --record file): every
// transaction the master accepted, with the frame it is in, written before the
// application hears that it was applied. What it is for:
//  - a master restarted with the same --record file (after a crash, kill -9
//    included) comes back with the live scene the journal leaves, and goes on
//    appending to it;
//  - --replay plays its last run again with no application connected, each
//    transaction in the frame it was in (demos, regression tests), and
//    render-reference --replay draws any frame of it.
// A run is what one start of the master wrote: a JournalStart, then its
// transactions (proto/optique/session.proto). No IO here but reading a
// --replay file; the master's shell writes the --record file.

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "master/session/live_scene.h"
#include "optique/session.pb.h"
#include "util/result.h"

namespace optique::master {

// What a journal file begins with: a file that does not is never read as one,
// nor cut, nor appended to.
inline constexpr std::string_view kJournalMagic = "optique journal 1\n";

// The largest entry a journal holds: a transaction is bounded by the session's
// message limit (master.max_message_bytes), far below this.
inline constexpr std::uint32_t kMaxJournalEntryBytes = 1u << 30;

// An entry as it is appended after the magic: its length (4 bytes,
// little-endian), then it.
[[nodiscard]] std::string journal_start(std::int64_t unix_ms, const std::string& scene_asset);
[[nodiscard]] std::string journal_transaction(std::uint64_t frame, const std::string& application,
                                              const session::Transaction& transaction);

// An asset loaded (LoadAsset), written before the application hears it may be
// instantiated.
[[nodiscard]] std::string journal_asset(std::uint64_t frame, const std::string& asset, const std::string& path,
                                        const std::string& sha256);

struct JournalRun {
  session::JournalStart start;
  std::vector<session::JournalTransaction> transactions;  // in the order they were accepted
};

struct Journal {
  std::vector<JournalRun> runs;
  // Every asset applications loaded, in any run, in order: the master loads
  // each again (and checks it is the same) before the transactions are applied.
  std::vector<session::JournalAsset> assets;
  // The bytes of the magic and the whole entries (0: not even the magic); what
  // follows them (`torn` says what it is) was a write cut short by a crash,
  // never acknowledged.
  std::uint64_t whole_bytes = 0;
  std::string torn;
};

// Reads a journal; an empty one has no runs. Fails on what no crash leaves
// behind: bytes that do not begin with kJournalMagic, and (naming the entry
// and its byte offset) an entry that is not one, a transaction before any
// start, an entry longer than kMaxJournalEntryBytes.
[[nodiscard]] Result<Journal> read_journal(std::string_view bytes);

// Reads the journal at `path` (--replay, render-reference --replay).
[[nodiscard]] Result<Journal> read_journal_file(const std::string& path);

// Applies every transaction of every run in order, each with a frame's budget
// of edits of its own (its assets added to `live` by the caller first). Fails
// when one is refused (the installation is not the one that wrote it: an
// asset gone, a smaller limit), naming it; `live` is then as the transactions
// before it left it. The transactions applied.
[[nodiscard]] Result<std::size_t> restore(LiveScene& live, const Journal& journal);

// The last run of a journal played again: the runs before it restored at once,
// then each of its transactions at the beginning of the frame it was in.
class JournalReplay {
 public:
  [[nodiscard]] static Result<JournalReplay> start(const Journal& journal, LiveScene& live);

  // Applies the transactions of every frame up to `frame` not applied yet (the
  // frame loop calls it as frame `frame` begins). Says why any was refused (a
  // journal from another installation); the rest go on.
  [[nodiscard]] std::vector<std::string> apply_due(LiveScene& live, std::uint64_t frame);

  [[nodiscard]] std::size_t left() const { return transactions_.size() - next_; }
  [[nodiscard]] std::size_t total() const { return transactions_.size(); }

 private:
  std::vector<session::JournalTransaction> transactions_;
  std::size_t next_ = 0;
};

// The live scene frame `frame` of a journal's last run shows when played
// again (what the master's frame loop puts in that frame with --replay), put
// into `state` (put_live): for render-reference --replay. `scene`: the
// installation's, at `frame_rate` Hz; `animated`: which of the journal's
// assets have animations.
[[nodiscard]] Result<void> replay_into(const Journal& journal, const scene::SceneDefinition& scene,
                                       LiveSceneLimits limits, double frame_rate, std::uint64_t frame,
                                       const std::set<std::string>& animated, scene::SceneState& state);

}  // namespace optique::master
