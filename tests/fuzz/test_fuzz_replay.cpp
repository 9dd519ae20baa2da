// The fuzz targets' bodies over the committed corpus, the generated seeds, and
// simple mutations of them (every truncation, every byte inverted): where clang or
// libFuzzer is missing this is the only fuzzing that runs, and it is deterministic.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_bodies.h"
#include "fuzz_seeds.h"

namespace optique::fuzz {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using Body = std::function<Outcome(std::span<const std::uint8_t>)>;

const fs::path kCorpus = OPTIQUE_FUZZ_CORPUS_DIR;

std::vector<fs::path> corpus_files(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kCorpus / target)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

Bytes read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Totals {
  int inputs = 0;
  int good_frames = 0;
  int envelopes = 0;
  int deltas_applied = 0;
  int deltas_refused = 0;
  int snapshots_accepted = 0;
};

void run(const Body& body, const std::string& name, std::span<const std::uint8_t> input, Totals& totals) {
  const Outcome outcome = body(input);
  EXPECT_TRUE(outcome.broken.empty()) << name << ": " << outcome.broken;
  ++totals.inputs;
  totals.good_frames += outcome.good_frames;
  totals.envelopes += outcome.envelopes;
  totals.deltas_applied += outcome.deltas_applied;
  totals.deltas_refused += outcome.deltas_refused;
  totals.snapshots_accepted += outcome.snapshot_accepted ? 1 : 0;
}

Totals replay_corpus(const Body& body, const std::string& target) {
  Totals totals;
  for (const fs::path& file : corpus_files(target)) run(body, file.string(), read_bytes(file), totals);
  return totals;
}

// Cuts and corrupts each seed: the cheap neighbours of valid inputs, where the
// decoders' edge cases are. The few big seeds are concatenations of small ones and
// would take most of the time (seconds under ASan) for little news.
Totals replay_mutations(const Body& body, const std::vector<Seed>& seeds) {
  constexpr std::size_t kMaxMutatedSeedBytes = 1024;
  Totals totals;
  for (const Seed& seed : seeds) {
    if (seed.bytes.size() > kMaxMutatedSeedBytes) continue;
    for (std::size_t n = 0; n < seed.bytes.size(); ++n) {
      run(body, seed.name + " cut to " + std::to_string(n), std::span(seed.bytes).first(n), totals);
    }
    Bytes flipped = seed.bytes;
    for (std::size_t i = 0; i < flipped.size(); ++i) {
      flipped[i] ^= 0xFF;
      run(body, seed.name + " byte " + std::to_string(i) + " inverted", flipped, totals);
      flipped[i] ^= 0xFF;
    }
  }
  return totals;
}

TEST(FuzzReplay, FrameCorpusHoldsInvariants) {
  const Totals totals = replay_corpus(run_frames, "frames");
  EXPECT_GE(totals.inputs, 20);
  // Each Envelope body type at least once on its own, and in the streams.
  EXPECT_GE(totals.envelopes, 14 * 2);
  EXPECT_GT(totals.good_frames, totals.envelopes);  // some good frames hold garbage
}

TEST(FuzzReplay, DeltaCorpusHoldsInvariants) {
  const Totals totals = replay_corpus(run_deltas, "deltas");
  EXPECT_GE(totals.inputs, 20);
  EXPECT_GE(totals.deltas_applied, 10);
  EXPECT_GE(totals.deltas_refused, 10);
  EXPECT_LT(totals.snapshots_accepted, totals.inputs);  // some snapshots are refused
}

TEST(FuzzReplay, ProtocolCorpusHoldsInvariants) {
  Totals totals;
  int finished = 0;
  int presented = 0;
  for (const fs::path& file : corpus_files("protocol")) {
    const Outcome outcome = run_protocol(read_bytes(file));
    EXPECT_TRUE(outcome.broken.empty()) << file << ": " << outcome.broken;
    ++totals.inputs;
    finished += outcome.finished ? 1 : 0;
    presented += outcome.frames_presented;
  }
  EXPECT_GE(totals.inputs, 6);
  EXPECT_EQ(finished, totals.inputs);
  EXPECT_GE(presented, 4 * 50) << "the runs get frames shown";
}

TEST(FuzzReplay, NodeCorpusHoldsInvariants) {
  int inputs = 0;
  int renders = 0;
  int closes = 0;
  int scene_chunks = 0;
  int assets_readied = 0;
  for (const fs::path& file : corpus_files("node")) {
    const Outcome outcome = run_node(read_bytes(file));
    EXPECT_TRUE(outcome.broken.empty()) << file << ": " << outcome.broken;
    ++inputs;
    renders += outcome.renders;
    closes += outcome.closes;
    scene_chunks += outcome.scene_chunks;
    assets_readied += outcome.assets_readied;
  }
  EXPECT_GE(inputs, 8);
  EXPECT_GE(renders, 4) << "some frames are drawn";
  EXPECT_GE(scene_chunks, 3) << "a scene's files are fetched";
  EXPECT_GE(assets_readied, 1) << "an asset offered in the frames is readied";
  EXPECT_GE(closes, 5) << "and the bad ones refused";
}

// Each node seed cut short and inverted byte by byte: the welcome's and the
// frames' decoders at their edges.
TEST(FuzzReplay, NodeSeedMutationsHoldInvariants) {
  const Totals totals = replay_mutations(
      [](std::span<const std::uint8_t> input) {
        Outcome outcome = run_node(input);
        outcome.envelopes = outcome.renders;  // counted as envelopes by replay_mutations
        return outcome;
      },
      node_seeds());
  EXPECT_GT(totals.envelopes, 0);
}

// The head tracker's datagrams: the corpus, then each seed cut and inverted.
TEST(FuzzReplay, TrackerCorpusHoldsInvariants) {
  int inputs = 0;
  int parsed = 0;
  int samples = 0;
  for (const fs::path& file : corpus_files("tracker")) {
    const Outcome outcome = run_tracker(read_bytes(file));
    EXPECT_TRUE(outcome.broken.empty()) << file << ": " << outcome.broken;
    ++inputs;
    parsed += outcome.datagrams_parsed;
    samples += outcome.samples;
  }
  EXPECT_GE(inputs, 8);
  EXPECT_GE(parsed, 20) << "most seeds are DTrack";
  EXPECT_GE(samples, 15) << "and the tracker takes their samples";
}

TEST(FuzzReplay, TrackerSeedMutationsHoldInvariants) {
  const Totals totals = replay_mutations(
      [](std::span<const std::uint8_t> input) {
        Outcome outcome = run_tracker(input);
        outcome.envelopes = outcome.datagrams_parsed;  // counted as envelopes by replay_mutations
        return outcome;
      },
      tracker_seeds());
  EXPECT_GT(totals.envelopes, 0);
}

// An application's messages to a scene session: the corpus, then each seed cut
// and inverted.
TEST(FuzzReplay, SessionCorpusHoldsInvariants) {
  int inputs = 0;
  int applied = 0;
  int refused = 0;
  for (const fs::path& file : corpus_files("session")) {
    const Outcome outcome = run_session(read_bytes(file));
    EXPECT_TRUE(outcome.broken.empty()) << file << ": " << outcome.broken;
    ++inputs;
    applied += outcome.applied;
    refused += outcome.refused;
  }
  EXPECT_GE(inputs, 5);
  EXPECT_GE(applied, 60) << "the live scene takes most placements";
  EXPECT_GE(refused, 12) << "and refuses what is wrong";
}

TEST(FuzzReplay, SessionSeedMutationsHoldInvariants) {
  const Totals totals = replay_mutations(run_session, session_seeds());
  EXPECT_GT(totals.envelopes, 0);
}

// The corpus is generated by optique-fuzz-corpus; a seed added to fuzz_seeds.cpp
// must land in the committed folder too.
TEST(FuzzReplay, CorpusHoldsEverySeed) {
  for (const auto& [target, seeds] : {std::pair{"frames", frame_seeds()}, std::pair{"deltas", delta_seeds()},
                                      std::pair{"protocol", protocol_seeds()}, std::pair{"node", node_seeds()},
                                      std::pair{"tracker", tracker_seeds()}, std::pair{"session", session_seeds()}}) {
    for (const Seed& seed : seeds) {
      EXPECT_TRUE(fs::exists(kCorpus / target / seed.name))
          << target << "/" << seed.name << " missing: cmake --build BUILD --target optique-fuzz-corpus && "
          << "BUILD/bin/optique-fuzz-corpus tests/fuzz/corpus";
    }
  }
}

TEST(FuzzReplay, FrameSeedMutationsHoldInvariants) {
  const Totals totals = replay_mutations(run_frames, frame_seeds());
  EXPECT_GT(totals.envelopes, 0);
}

TEST(FuzzReplay, DeltaSeedMutationsHoldInvariants) {
  const Totals totals = replay_mutations(run_deltas, delta_seeds());
  EXPECT_GT(totals.deltas_applied, 0);
  EXPECT_GT(totals.deltas_refused, 0);
}

}  // namespace
}  // namespace optique::fuzz
