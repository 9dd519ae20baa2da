// A node's copies of the master's scenes (node/scene_cache.h), on a real file
// system under a temporary folder: a copy is written and put in place; a spoilt
// copy is not used; a copy cut short goes on from the chunks it holds; partial
// copies whose node is gone (no one holds their lock) go; when the disk is short
// (a small tmpfs, where this runs as root, or a disk of a given size the test
// hands in) the copies used longest ago make room, and none goes when that
// would not make room anyway.

#include "node/scene_cache.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/null_sink.h>
#include <spdlog/sinks/ostream_sink.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <thread>
#include <variant>

#include "scene/manifest.h"
#include "scratch.h"

namespace optique::node {
namespace {

namespace fs = std::filesystem;

class SceneCacheTest : public ::testing::Test {
 protected:
  // Writes chunks of the scene through `cache` as a fetch would; all of them
  // unless `only` names one (file, chunk).
  void write_chunks(SceneCache& cache, std::optional<std::pair<std::uint32_t, std::uint64_t>> only = {}) {
    const std::vector<const std::string*> contents{&gltf_, &bin_};
    for (std::uint32_t f = 0; f < 2; ++f) {
      for (std::uint64_t c = 0; c < files_.files[f].chunks(files_.chunk_bytes); ++c) {
        if (only && *only != std::make_pair(f, c)) continue;
        const std::string data = contents[f]->substr(files_.chunk_offset(c), files_.chunk_length(f, c));
        ASSERT_TRUE(cache.write(f, files_.chunk_offset(c), data).ok());
      }
    }
  }

  // A fetch of the whole scene; `wait_for_others` false: even while another
  // node fetches it (SceneCache::begin).
  Result<std::string> fetch(SceneCache& cache, bool wait_for_others = true) {
    auto begun = cache.begin(files_, sha_, wait_for_others);
    if (!begun) return Error{begun.error()};
    if (!std::holds_alternative<SceneCache::Present>(begun.value())) return Error{"another node fetches the scene"};
    write_chunks(cache);
    return cache.commit();
  }

  // Copies and partial copies with their locks; not the folder's lock for
  // beginning a copy (.begin), which stays.
  int entries_in_scenes() const {
    int entries = 0;
    for (const auto& entry : fs::directory_iterator(dir_ / "scenes")) entries += entry.path().filename() != ".begin";
    return entries;
  }

  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  // Copies of other scenes, `bytes` each, in `folder`/scenes: the first used
  // longest ago.
  static std::vector<fs::path> other_copies(const fs::path& folder, std::size_t count, std::size_t bytes) {
    std::vector<fs::path> copies;
    const auto now = fs::file_time_type::clock::now();
    for (std::size_t i = 0; i < count; ++i) {
      copies.push_back(folder / "scenes" / std::string(64, static_cast<char>('a' + i)));
      fs::create_directories(copies.back() / "maps");
      std::ofstream(copies.back() / "maps" / "big.bin", std::ios::binary) << std::string(bytes, 'x');
      fs::last_write_time(copies.back(), now - std::chrono::hours(10 - static_cast<int>(i)));
    }
    return copies;
  }

  // A disk of `capacity` bytes that holds what is under dir_ and nothing else.
  SceneCache::FreeSpace disk_of(std::uintmax_t capacity) const {
    return [this, capacity](const fs::path&) -> Result<std::uintmax_t> {
      std::uintmax_t used = 0;
      for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
        if (entry.is_regular_file()) used += entry.file_size();
      }
      return used >= capacity ? 0 : capacity - used;
    };
  }

  std::ostringstream log_text_;
  spdlog::logger log_{"node", std::make_shared<spdlog::sinks::ostream_sink_st>(log_text_)};
  optique::testing::ScratchDir scratch_{"optique-cache"};
  fs::path dir_ = scratch_.path();
  std::string gltf_ = R"({"asset":{"version":"2.0"}})";
  std::string bin_ = std::string(10000, '\x61');
  scene::SceneManifest files_{
      4096, {scene::describe_file("s.gltf", gltf_, 4096), scene::describe_file("maps/s.bin", bin_, 4096)}};
  std::string sha_ = scene::manifest_sha256(files_);
};

TEST_F(SceneCacheTest, AFetchedCopyIsPutInPlaceAndFoundAgainAfterARestart) {
  SceneCache cache(dir_, log_);
  EXPECT_EQ(cache.folder(), dir_ / "scenes");
  EXPECT_FALSE(cache.find(files_, sha_).has_value());
  auto stored = fetch(cache);
  ASSERT_TRUE(stored.ok()) << stored.error();
  EXPECT_EQ(stored.value(), (dir_ / "scenes" / sha_ / "s.gltf").string());
  EXPECT_EQ(read(dir_ / "scenes" / sha_ / "maps/s.bin"), bin_);
  EXPECT_EQ(entries_in_scenes(), 1) << "no partial copy or lock is left beside it";
  SceneCache restarted(dir_, log_);
  EXPECT_EQ(restarted.find(files_, sha_), stored.value());
}

TEST_F(SceneCacheTest, ASpoiltCopyIsNotUsedButRemoved) {
  SceneCache cache(dir_, log_);
  ASSERT_TRUE(fetch(cache).ok());
  {
    std::fstream file(dir_ / "scenes" / sha_ / "maps/s.bin", std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(5000);
    file.put('b');
  }
  SceneCache restarted(dir_, log_);
  EXPECT_FALSE(restarted.find(files_, sha_).has_value());
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / sha_));
  // The log says which file and what was wrong, not only that there is no copy.
  const std::string logged = log_text_.str();
  EXPECT_NE(logged.find("is spoilt ("), std::string::npos) << logged;
  EXPECT_NE(logged.find((dir_ / "scenes" / sha_ / "maps/s.bin").string() + " does not match its SHA-256"),
            std::string::npos)
      << logged;
  EXPECT_NE(logged.find(sha_.substr(0, 12)), std::string::npos) << logged;
}

TEST_F(SceneCacheTest, ACopyWithAFileMissingSaysWhich) {
  SceneCache cache(dir_, log_);
  ASSERT_TRUE(fetch(cache).ok());
  fs::remove(dir_ / "scenes" / sha_ / "s.gltf");
  SceneCache restarted(dir_, log_);
  EXPECT_FALSE(restarted.find(files_, sha_).has_value());
  const std::string logged = log_text_.str();
  EXPECT_NE(logged.find((dir_ / "scenes" / sha_ / "s.gltf").string() + ": No such file"), std::string::npos) << logged;
}

TEST_F(SceneCacheTest, ACopyMissingChunksIsNotPutInPlace) {
  SceneCache cache(dir_, log_);
  ASSERT_TRUE(cache.begin(files_, sha_).ok());
  write_chunks(cache, std::make_pair(1u, std::uint64_t{0}));
  const auto committed = cache.commit();
  ASSERT_FALSE(committed.ok());
  EXPECT_NE(committed.error().find("not whole: " + (dir_ / "scenes").string()), std::string::npos)
      << "names the file where it is: " << committed.error();
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / sha_));
  EXPECT_EQ(entries_in_scenes(), 0) << "the partial copy and its lock are removed";
}

// A chunk that did not reach the disk leaves a hole in a file already at its
// full size (the chunks after it were written): the copy is not put in place.
// The disk refuses here through the file-size limit (EFBIG), as a full disk would.
TEST_F(SceneCacheTest, ACopyWithAChunkTheDiskRefusedIsNotPutInPlace) {
  SceneCache cache(dir_, log_);
  ASSERT_TRUE(cache.begin(files_, sha_).ok());
  write_chunks(cache, std::make_pair(0u, std::uint64_t{0}));
  write_chunks(cache, std::make_pair(1u, std::uint64_t{0}));
  write_chunks(cache, std::make_pair(1u, std::uint64_t{2}));  // the file is at its full size now
  rlimit before{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &before), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = before;
  small.rlim_cur = files_.chunk_bytes;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string middle = bin_.substr(files_.chunk_offset(1), files_.chunk_length(1, 1));
  const Result<void> refused = cache.write(1, files_.chunk_offset(1), middle);
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &before), 0);
  std::signal(SIGXFSZ, old_handler);
  ASSERT_FALSE(refused.ok()) << "the limit did not stop the write";
  const auto committed = cache.commit();
  ASSERT_FALSE(committed.ok()) << "a copy with a hole was put in place";
  EXPECT_NE(committed.error().find("not whole: cannot write " + (dir_ / "scenes").string()), std::string::npos)
      << committed.error();
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / sha_));
  EXPECT_EQ(entries_in_scenes(), 0) << "the partial copy and its lock are removed";
}

TEST_F(SceneCacheTest, ACopyCutShortGoesOnFromTheChunksItHolds) {
  SceneCache cache(dir_, log_);
  auto begun = cache.begin(files_, sha_);
  ASSERT_TRUE(begun.ok());
  EXPECT_EQ(std::get<SceneCache::Present>(begun.value()), (SceneCache::Present{{false}, {false, false, false}}));
  write_chunks(cache, std::make_pair(0u, std::uint64_t{0}));
  write_chunks(cache, std::make_pair(1u, std::uint64_t{1}));
  // The connection went; the fetch starts again on the same copy.
  begun = cache.begin(files_, sha_);
  ASSERT_TRUE(begun.ok());
  EXPECT_EQ(std::get<SceneCache::Present>(begun.value()), (SceneCache::Present{{true}, {false, true, false}}));
  write_chunks(cache, std::make_pair(1u, std::uint64_t{0}));
  write_chunks(cache, std::make_pair(1u, std::uint64_t{2}));
  const auto committed = cache.commit();
  ASSERT_TRUE(committed.ok()) << committed.error();
  EXPECT_EQ(read(dir_ / "scenes" / sha_ / "maps/s.bin"), bin_);
}

// The second node of a host to begin the scene waits for the first's copy,
// seeing it grow; once it is in place, the second finds it.
TEST_F(SceneCacheTest, TheSecondNodeToBeginWaitsForTheFirstsCopy) {
  SceneCache first(dir_, log_);
  SceneCache second(dir_, log_);
  ASSERT_TRUE(first.begin(files_, sha_).ok());
  auto begun = second.begin(files_, sha_);
  ASSERT_TRUE(begun.ok()) << begun.error();
  ASSERT_TRUE(std::holds_alternative<SceneCache::FetchedElsewhere>(begun.value()));
  EXPECT_EQ(std::get<SceneCache::FetchedElsewhere>(begun.value()).bytes_there, 0u);
  write_chunks(first, std::make_pair(1u, std::uint64_t{0}));
  begun = second.begin(files_, sha_);
  ASSERT_TRUE(begun.ok()) << begun.error();
  ASSERT_TRUE(std::holds_alternative<SceneCache::FetchedElsewhere>(begun.value()));
  // The disk's blocks: at least the chunk, and not more than the scene.
  EXPECT_GE(std::get<SceneCache::FetchedElsewhere>(begun.value()).bytes_there, files_.chunk_length(1, 0));
  EXPECT_LE(std::get<SceneCache::FetchedElsewhere>(begun.value()).bytes_there, files_.total_bytes() + 4096);
  EXPECT_FALSE(second.find(files_, sha_).has_value());
  write_chunks(first);
  ASSERT_TRUE(first.commit().ok());
  const auto found = second.find(files_, sha_);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(read(*found), gltf_);
  EXPECT_EQ(entries_in_scenes(), 1) << "the copy in place, no partial copy";
}

// The first node stops midway: the one waiting takes its copy over.
TEST_F(SceneCacheTest, TheNodeWaitingTakesOverTheCopyOfOneThatStopped) {
  SceneCache second(dir_, log_);
  {
    SceneCache first(dir_, log_);
    ASSERT_TRUE(first.begin(files_, sha_).ok());
    write_chunks(first, std::make_pair(1u, std::uint64_t{1}));
    const auto waiting = second.begin(files_, sha_);
    ASSERT_TRUE(waiting.ok() && std::holds_alternative<SceneCache::FetchedElsewhere>(waiting.value()));
  }
  auto begun = second.begin(files_, sha_);
  ASSERT_TRUE(begun.ok()) << begun.error();
  ASSERT_TRUE(std::holds_alternative<SceneCache::Present>(begun.value()));
  EXPECT_EQ(std::get<SceneCache::Present>(begun.value()), (SceneCache::Present{{false}, {false, true, false}}));
}

// Two that begin at once: exactly one of them fetches (the folder's lock makes
// the look and the start one step).
TEST_F(SceneCacheTest, OfTwoNodesBeginningAtOnceOneFetches) {
  for (int round = 0; round < 20; ++round) {
    fs::remove_all(dir_ / "scenes");
    SceneCache first(dir_, log_);
    SceneCache second(dir_, log_);
    Result<SceneCache::Begun> a = Error{"not begun"};
    Result<SceneCache::Begun> b = Error{"not begun"};
    std::thread other([&] { a = first.begin(files_, sha_); });
    b = second.begin(files_, sha_);
    other.join();
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_NE(std::holds_alternative<SceneCache::Present>(a.value()),
              std::holds_alternative<SceneCache::Present>(b.value()))
        << "round " << round;
  }
}

// One that gave up waiting (the other's copy stopped growing) writes its own:
// whichever finishes first is put in place and the other uses it.
TEST_F(SceneCacheTest, TwoNodesOfOneHostFetchingTogetherShareTheCopy) {
  SceneCache first(dir_, log_);
  SceneCache second(dir_, log_);
  ASSERT_TRUE(first.begin(files_, sha_).ok());
  auto by_second = fetch(second, false);  // finishes first; first's partial copy is left alone
  ASSERT_TRUE(by_second.ok()) << by_second.error();
  write_chunks(first);
  const auto by_first = first.commit();
  ASSERT_TRUE(by_first.ok()) << by_first.error();
  EXPECT_EQ(by_first.value(), by_second.value());
  EXPECT_EQ(entries_in_scenes(), 1);
}

// A node killed midway leaves its partial copy and its lock file; the next
// node to fetch the scene (the same one restarted, or another of this host)
// takes it over with the chunks it holds, and one still held is left alone.
TEST_F(SceneCacheTest, ACopyLeftByAStoppedNodeIsTakenOverWithItsChunks) {
  SceneCache held(dir_, log_);  // a node of this host fetching it too
  {
    SceneCache stopped(dir_, log_);
    ASSERT_TRUE(stopped.begin(files_, sha_).ok());
    write_chunks(stopped, std::make_pair(0u, std::uint64_t{0}));
    write_chunks(stopped, std::make_pair(1u, std::uint64_t{2}));
    ASSERT_TRUE(held.begin(files_, sha_, false).ok());
  }  // its process ends without abandoning the copy: the lock is let go
  // Its glTF ran past its size (a crash mid-write): cut to its size, the chunk is kept.
  for (const auto& entry : fs::directory_iterator(dir_ / "scenes")) {
    const fs::path gltf = entry.path() / "s.gltf";
    if (fs::is_directory(entry.path()) && fs::exists(gltf) && fs::file_size(gltf) == gltf_.size()) {
      std::ofstream(gltf, std::ios::binary | std::ios::app) << "junk";
    }
  }
  SceneCache restarted(dir_, log_);
  auto begun = restarted.begin(files_, sha_, false);  // not waiting for `held`
  ASSERT_TRUE(begun.ok()) << begun.error();
  EXPECT_EQ(std::get<SceneCache::Present>(begun.value()), (SceneCache::Present{{true}, {false, false, true}}));
  EXPECT_NE(log_text_.str().find("that a stopped node left: 2 of its 4 chunks are in"), std::string::npos)
      << log_text_.str();
  write_chunks(restarted, std::make_pair(1u, std::uint64_t{0}));
  write_chunks(restarted, std::make_pair(1u, std::uint64_t{1}));
  const auto committed = restarted.commit();
  ASSERT_TRUE(committed.ok()) << committed.error();
  EXPECT_EQ(read(dir_ / "scenes" / sha_ / "maps/s.bin"), bin_);
  EXPECT_EQ(read(dir_ / "scenes" / sha_ / "s.gltf"), gltf_);
  held.abandon();
  EXPECT_EQ(entries_in_scenes(), 1) << "the copy in place; no partial copy, no lock";
}

TEST_F(SceneCacheTest, PartialCopiesWhoseNodeIsGoneAreRemovedAndOthersKept) {
  SceneCache alive(dir_, log_);
  const scene::SceneManifest other{4096, {scene::describe_file("o.gltf", "{}", 4096)}};
  ASSERT_TRUE(alive.begin(other, scene::manifest_sha256(other)).ok());  // holds its lock
  const std::string gone = std::string(64, 'e');                        // another scene's
  fs::create_directories(dir_ / "scenes" / (sha_ + ".partial-1-2"));    // no lock file: its node died early
  fs::create_directories(dir_ / "scenes" / (gone + ".partial-3-4"));
  std::ofstream(dir_ / "scenes" / (gone + ".partial-3-4.lock")) << "";  // a lock nobody holds
  SceneCache cache(dir_, log_);
  ASSERT_TRUE(cache.begin(files_, sha_).ok());
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / (sha_ + ".partial-1-2")));
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / (gone + ".partial-3-4")));
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / (gone + ".partial-3-4.lock")));
  // alive's partial and lock, cache's partial and lock.
  EXPECT_EQ(entries_in_scenes(), 4);
  cache.abandon();
  alive.abandon();
  EXPECT_EQ(entries_in_scenes(), 0);
}

TEST_F(SceneCacheTest, WhenTheDiskIsShortTheCopiesUsedLongestAgoMakeRoom) {
  const fs::path small = dir_ / "small";
  fs::create_directories(small);
  if (mount("tmpfs", small.c_str(), "tmpfs", 0, "size=1m") != 0) {
    GTEST_SKIP() << "a small tmpfs needs root: " << std::strerror(errno);
  }
  struct Unmount {
    const fs::path& at;
    ~Unmount() { umount(at.c_str()); }
  } unmount{small};
  {
    // Two copies of other scenes, 400 KiB each, the first used longer ago.
    const std::string fake = std::string(64, 'a');
    const std::string used = std::string(64, 'b');
    for (const std::string& name : {fake, used}) {
      fs::create_directories(small / "scenes" / name);
      std::ofstream(small / "scenes" / name / "big.bin", std::ios::binary) << std::string(400 << 10, 'x');
    }
    const auto now = fs::file_time_type::clock::now();
    fs::last_write_time(small / "scenes" / fake, now - std::chrono::hours(2));
    fs::last_write_time(small / "scenes" / used, now - std::chrono::hours(1));
    const scene::SceneManifest big{4096, {scene::describe_file("big.gltf", std::string(300 << 10, 'y'), 4096)}};
    SceneCache cache(small, log_, 0);
    ASSERT_TRUE(cache.begin(big, scene::manifest_sha256(big)).ok());
    EXPECT_FALSE(fs::exists(small / "scenes" / fake)) << "used longest ago: removed";
    EXPECT_TRUE(fs::exists(small / "scenes" / used));
    cache.abandon();
    // More than the disk holds at all: refused, naming the folder.
    const scene::SceneManifest huge{4096, {scene::describe_file("huge.gltf", std::string(2 << 20, 'z'), 4096)}};
    const auto refused = cache.begin(huge, scene::manifest_sha256(huge));
    ASSERT_FALSE(refused.ok());
    EXPECT_NE(refused.error().find((small / "scenes").string()), std::string::npos) << refused.error();
  }
}

TEST_F(SceneCacheTest, OnAShortDiskOnlyTheCopiesUsedLongestAgoThatMakeRoomGo) {
  // 1 MiB; three copies of 256 KiB: 256 KiB free. A scene of 600 KiB and 64 KiB
  // spare needs 664: the two used longest ago go, the third stays.
  const auto copies = other_copies(dir_, 3, 256 << 10);
  SceneCache cache(dir_, log_, 64 << 10, disk_of(1 << 20));
  const scene::SceneManifest big{4096, {scene::describe_file("big.gltf", std::string(600 << 10, 'y'), 4096)}};
  const auto begun = cache.begin(big, scene::manifest_sha256(big));
  ASSERT_TRUE(begun.ok()) << begun.error();
  EXPECT_FALSE(fs::exists(copies[0]));
  EXPECT_FALSE(fs::exists(copies[1]));
  EXPECT_TRUE(fs::exists(copies[2])) << "not needed gone";
}

TEST_F(SceneCacheTest, ASceneThatWouldNotFitEvenWithEveryCopyGoneCostsNone) {
  // 1 MiB; two copies of 256 KiB: 512 KiB free, 1 MiB with both gone. A scene of
  // 2 MiB (well within --max-scene-mb) cannot fit: both copies stay.
  const auto copies = other_copies(dir_, 2, 256 << 10);
  SceneCache cache(dir_, log_, 64 << 10, disk_of(1 << 20));
  const scene::SceneManifest huge{4096, {scene::describe_file("huge.gltf", std::string(2 << 20, 'z'), 4096)}};
  const auto refused = cache.begin(huge, scene::manifest_sha256(huge));
  ASSERT_FALSE(refused.ok());
  EXPECT_TRUE(fs::exists(copies[0]));
  EXPECT_TRUE(fs::exists(copies[1]));
  const std::string& why = refused.error();
  EXPECT_NE(why.find((dir_ / "scenes").string()), std::string::npos) << why;
  EXPECT_NE(why.find("has 0.5 MiB free"), std::string::npos) << why;
  EXPECT_NE(why.find("removing every other copy (2) would free 0.5 MiB more"), std::string::npos) << why;
  EXPECT_NE(why.find("the scene needs 2.1 MiB (2.0 MiB and 0.1 MiB kept free)"), std::string::npos) << why;
  EXPECT_NE(why.find("none was removed"), std::string::npos) << why;
  EXPECT_EQ(entries_in_scenes(), 2) << "no partial copy or lock either";
}

TEST_F(SceneCacheTest, AFolderThatCannotBeWrittenSaysSo) {
  std::ofstream(dir_ / "file") << "not a folder";
  SceneCache cache(dir_ / "file", log_);
  const auto begun = cache.begin(files_, sha_);
  ASSERT_FALSE(begun.ok());
  EXPECT_NE(begun.error().find((dir_ / "file").string()), std::string::npos) << begun.error();
}

}  // namespace
}  // namespace optique::node
