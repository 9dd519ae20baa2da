// The live scene's journal (master/session/journal.h): what is appended reads
// back; a write a crash cut short is set apart, anything else that is not a
// journal is refused with the entry and its byte; restoring and replaying
// apply the transactions as they were accepted.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "master/session/journal.h"

namespace optique::master {
namespace {

session::Transaction create(const std::string& instance, double x = 0.0) {
  session::Transaction t;
  auto& c = *t.add_edits()->mutable_create();
  c.set_instance(instance);
  c.set_asset("torus");
  c.mutable_transform()->add_position(x);
  c.mutable_transform()->add_position(0.0);
  c.mutable_transform()->add_position(0.0);
  return t;
}

session::Transaction remove(const std::string& instance) {
  session::Transaction t;
  t.add_edits()->mutable_remove()->set_instance(instance);
  return t;
}

LiveScene with_torus() {
  LiveScene live;
  live.add_asset("torus");
  return live;
}

// Two runs: t1 and t2 made, then (after a restart) t1 removed and t3 made.
std::string two_runs() {
  return std::string(kJournalMagic) + journal_start(1000, "torus") + journal_transaction(3, "app", create("t1")) +
         journal_transaction(3, "app", create("t2", 1.0)) + journal_start(2000, "torus") +
         journal_transaction(5, "app", remove("t1")) + journal_transaction(9, "other", create("t3"));
}

TEST(Journal, WhatIsAppendedReadsBack) {
  auto read = read_journal(two_runs());
  ASSERT_TRUE(read.ok()) << read.error();
  const Journal& journal = read.value();
  EXPECT_EQ(journal.whole_bytes, two_runs().size());
  EXPECT_EQ(journal.torn, "");
  ASSERT_EQ(journal.runs.size(), 2u);
  EXPECT_EQ(journal.runs[0].start.unix_ms(), 1000);
  EXPECT_EQ(journal.runs[0].start.scene_asset(), "torus");
  ASSERT_EQ(journal.runs[0].transactions.size(), 2u);
  EXPECT_EQ(journal.runs[0].transactions[1].frame(), 3u);
  EXPECT_EQ(journal.runs[0].transactions[1].transaction().edits(0).create().instance(), "t2");
  ASSERT_EQ(journal.runs[1].transactions.size(), 2u);
  EXPECT_EQ(journal.runs[1].transactions[1].application(), "other");
  auto empty = read_journal("");
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty.value().runs.empty());
}

// Cut anywhere, a journal reads as the whole entries before the cut, and says
// where the torn one began: what a crash in the middle of a write leaves.
TEST(Journal, ACutAnywhereKeepsTheWholeEntriesBeforeIt) {
  const std::string bytes = two_runs();
  std::vector<std::size_t> ends{kJournalMagic.size()};  // where the magic and each entry end
  for (std::size_t at = kJournalMagic.size(); at < bytes.size();) {
    const std::size_t length = static_cast<std::uint8_t>(bytes[at]) | static_cast<std::uint8_t>(bytes[at + 1]) << 8;
    at += 4 + length;
    ends.push_back(at);
  }
  ASSERT_EQ(ends.size(), 7u);
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    auto read = read_journal(std::string_view(bytes).substr(0, cut));
    ASSERT_TRUE(read.ok()) << "cut at " << cut << ": " << read.error();
    std::size_t whole = 0;
    for (std::size_t end : ends) {
      if (end <= cut) whole = end;
    }
    EXPECT_EQ(read.value().whole_bytes, whole) << "cut at " << cut;
    EXPECT_EQ(read.value().torn.empty(), whole == cut) << "cut at " << cut;
  }
}

TEST(Journal, WhatNoCrashLeavesIsRefusedWithTheEntryAndItsByte) {
  const std::string magic(kJournalMagic);
  const std::string start = magic + journal_start(0, "torus");
  const std::string transaction = journal_transaction(4, "app", create("t1"));
  struct Case {
    std::string bytes;
    std::string error;
  };
  const std::string huge_length("\xff\xff\xff\x7f", 4);
  const std::string not_an_entry = std::string("\x03\x00\x00\x00", 4) + "\xff\xff\xff";
  const std::vector<Case> cases = {
      {magic + transaction, "entry 1 at byte 18: a transaction before the journal's first start"},
      {"not a journal at all",
       "does not begin with \"optique journal 1\": not a journal (nothing in it was read or "
       "changed)"},
      {transaction, "does not begin with \"optique journal 1\": not a journal (nothing in it was read or changed)"},
      {start + huge_length, "entry 2 at byte " + std::to_string(start.size()) +
                                ": says it is 2147483647 bytes long; no entry is over 1073741824 (is this a journal?)"},
      {start + not_an_entry,
       "entry 2 at byte " + std::to_string(start.size()) + ": is not a journal entry (is this a journal?)"},
      {start + transaction + journal_transaction(3, "app", create("t2")),
       "entry 3 at byte " + std::to_string(start.size() + transaction.size()) +
           ": its frame 3 is before the frame of the transaction before it (4)"},
      {start + std::string(4, '\0'),
       "entry 2 at byte " + std::to_string(start.size()) + ": an entry of a kind this master does not know"},
  };
  for (const Case& c : cases) {
    auto read = read_journal(c.bytes);
    ASSERT_FALSE(read.ok()) << c.error;
    EXPECT_EQ(read.error(), c.error);
  }
}

TEST(Journal, RestoringAppliesEveryRunInOrder) {
  auto read = read_journal(two_runs());
  ASSERT_TRUE(read.ok());
  LiveScene live = with_torus();
  auto restored = restore(live, read.value());
  ASSERT_TRUE(restored.ok()) << restored.error();
  EXPECT_EQ(restored.value(), 4u);
  ASSERT_EQ(live.instances().size(), 2u);
  EXPECT_TRUE(live.instances().contains("t2"));
  EXPECT_TRUE(live.instances().contains("t3"));
  EXPECT_EQ(live.instances().at("t2").pose.position.x, 1.0);
}

// A journal written for another installation (here: one without the asset)
// is refused, naming the transaction, rather than half restored in silence.
TEST(Journal, AJournalOfAnotherInstallationIsRefusedByName) {
  auto read = read_journal(two_runs());
  ASSERT_TRUE(read.ok());
  LiveScene live;
  live.add_asset("cubes");
  auto restored = restore(live, read.value());
  ASSERT_FALSE(restored.ok());
  EXPECT_EQ(restored.error(),
            "run 1, transaction 1 (frame 3, from 'app') was refused: edits[0].create.asset: no asset 'torus' is "
            "loaded; the journal was written for another installation");
}

// Each transaction of a frame's budget of its own: a journal is restored even
// when its transactions together are more edits than one frame takes.
TEST(Journal, RestoringGivesEachTransactionAFramesBudget) {
  std::string bytes = std::string(kJournalMagic) + journal_start(0, "torus");
  for (int i = 0; i < 5; ++i) {
    bytes += journal_transaction(static_cast<std::uint64_t>(i), "app", create("t" + std::to_string(i)));
  }
  auto read = read_journal(bytes);
  ASSERT_TRUE(read.ok());
  LiveSceneLimits limits;
  limits.max_edits_per_frame = 1;
  LiveScene live(limits);
  live.add_asset("torus");
  auto restored = restore(live, read.value());
  ASSERT_TRUE(restored.ok()) << restored.error();
  EXPECT_EQ(live.instances().size(), 5u);
}

// The last run played again: the runs before it at once, then each of its
// transactions as its frame begins, never before.
TEST(Journal, AReplayAppliesTheLastRunFrameByFrame) {
  auto read = read_journal(two_runs());
  ASSERT_TRUE(read.ok());
  LiveScene live = with_torus();
  auto replay = JournalReplay::start(read.value(), live);
  ASSERT_TRUE(replay.ok()) << replay.error();
  EXPECT_EQ(live.instances().size(), 2u) << "the first run restored: t1 and t2";
  EXPECT_EQ(replay.value().total(), 2u);
  for (std::uint64_t frame = 0; frame <= 10; ++frame) {
    EXPECT_EQ(replay.value().apply_due(live, frame), std::vector<std::string>{});
    live.begin_frame();
    EXPECT_EQ(live.instances().contains("t1"), frame < 5) << frame;
    EXPECT_EQ(live.instances().contains("t3"), frame >= 9) << frame;
  }
  EXPECT_EQ(replay.value().left(), 0u);

  // A transaction the scene refuses is named; the rest go on.
  LiveScene again = with_torus();
  auto second = JournalReplay::start(read.value(), again);
  ASSERT_TRUE(second.ok());
  ASSERT_FALSE(again.apply(remove("t1"), 0));
  const auto problems = second.value().apply_due(again, 100);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0],
            "replaying the journal: transaction 1 (frame 5) was refused: edits[0].remove.instance: no instance 't1'");
  EXPECT_TRUE(again.instances().contains("t3"));
}

}  // namespace
}  // namespace optique::master
