// A node's copies of the master's scenes (node/scene_cache.h), on a real file
// system under a temporary folder: a copy is written, checked whole and put in
// place; a spoilt copy is not used; partial copies of nodes that are gone go.

#include "node/scene_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "scene/manifest.h"

namespace optique::node {
namespace {

namespace fs = std::filesystem;

class SceneCacheTest : public ::testing::Test {
 protected:
  SceneCacheTest() {
    std::string pattern = (fs::temp_directory_path() / "optique-cache-XXXXXX").string();
    EXPECT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  ~SceneCacheTest() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // Writes the whole scene through `cache` as a fetch would, chunk by chunk.
  Result<std::string> fetch(SceneCache& cache) {
    if (auto begun = cache.begin(files_, sha_); !begun) return Error{begun.error()};
    const std::vector<const std::string*> contents{&gltf_, &bin_};
    for (std::uint32_t f = 0; f < 2; ++f) {
      for (std::uint64_t c = 0; c < files_.files[f].chunks(files_.chunk_bytes); ++c) {
        const std::string data =
            contents[f]->substr(files_.chunk_offset(c), files_.chunk_length(f, c));
        if (auto written = cache.write(f, files_.chunk_offset(c), data); !written) return Error{written.error()};
      }
    }
    return cache.commit();
  }

  static std::string read(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
  std::string gltf_ = R"({"asset":{"version":"2.0"}})";
  std::string bin_ = std::string(10000, '\x61');
  scene::SceneManifest files_{4096, {scene::describe_file("s.gltf", gltf_, 4096),
                                     scene::describe_file("maps/s.bin", bin_, 4096)}};
  std::string sha_ = scene::manifest_sha256(files_);
};

TEST_F(SceneCacheTest, AFetchedCopyIsPutInPlaceAndFoundAgainAfterARestart) {
  SceneCache cache(dir_);
  EXPECT_EQ(cache.folder(), dir_ / "scenes");
  EXPECT_FALSE(cache.find(files_, sha_).has_value());
  auto stored = fetch(cache);
  ASSERT_TRUE(stored.ok()) << stored.error();
  EXPECT_EQ(stored.value(), (dir_ / "scenes" / sha_ / "s.gltf").string());
  EXPECT_EQ(read(dir_ / "scenes" / sha_ / "maps/s.bin"), bin_);
  // No partial copy is left beside it.
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_ / "scenes")) ++entries;
  EXPECT_EQ(entries, 1);
  SceneCache restarted(dir_);
  EXPECT_EQ(restarted.find(files_, sha_), stored.value());
}

TEST_F(SceneCacheTest, ASpoiltCopyIsNotUsedButRemoved) {
  SceneCache cache(dir_);
  ASSERT_TRUE(fetch(cache).ok());
  {
    std::fstream file(dir_ / "scenes" / sha_ / "maps/s.bin", std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(5000);
    file.put('b');
  }
  SceneCache restarted(dir_);
  EXPECT_FALSE(restarted.find(files_, sha_).has_value());
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / sha_));
}

TEST_F(SceneCacheTest, ACopyThatIsNotWholeIsNotPutInPlace) {
  SceneCache cache(dir_);
  ASSERT_TRUE(cache.begin(files_, sha_).ok());
  ASSERT_TRUE(cache.write(0, 0, gltf_).ok());
  ASSERT_TRUE(cache.write(1, 0, std::string(4096, 'z')).ok());  // what no chunk check would let through
  const auto committed = cache.commit();
  ASSERT_FALSE(committed.ok());
  EXPECT_NE(committed.error().find("not whole"), std::string::npos) << committed.error();
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / sha_));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_ / "scenes")) ++entries;
  EXPECT_EQ(entries, 0) << "the partial copy is removed";
}

TEST_F(SceneCacheTest, TwoNodesOfOneMachineFetchingTogetherShareTheCopy) {
  SceneCache first(dir_);
  SceneCache second(dir_);
  ASSERT_TRUE(first.begin(files_, sha_).ok());
  auto by_second = fetch(second);  // finishes first
  ASSERT_TRUE(by_second.ok()) << by_second.error();
  ASSERT_TRUE(first.write(0, 0, gltf_).ok());
  for (std::uint64_t c = 0; c < 3; ++c) {
    ASSERT_TRUE(first.write(1, c * 4096, bin_.substr(c * 4096, files_.chunk_length(1, c))).ok());
  }
  const auto by_first = first.commit();
  ASSERT_TRUE(by_first.ok()) << by_first.error();
  EXPECT_EQ(by_first.value(), by_second.value());
}

TEST_F(SceneCacheTest, PartialCopiesOfNodesThatAreGoneAreRemoved) {
  fs::create_directories(dir_ / "scenes" / (sha_ + ".partial-999999999"));  // no such process
  fs::create_directories(dir_ / "scenes" / (sha_ + ".partial-1"));          // init: alive
  SceneCache cache(dir_);
  ASSERT_TRUE(cache.begin(files_, sha_).ok());
  EXPECT_FALSE(fs::exists(dir_ / "scenes" / (sha_ + ".partial-999999999")));
  EXPECT_TRUE(fs::exists(dir_ / "scenes" / (sha_ + ".partial-1")));
  cache.abandon();
  int ours = 0;
  for (const auto& entry : fs::directory_iterator(dir_ / "scenes")) {
    ours += entry.path().filename().string().starts_with(sha_ + ".partial-" + std::to_string(getpid())) ? 1 : 0;
  }
  EXPECT_EQ(ours, 0) << "abandoned: removed";
}

TEST_F(SceneCacheTest, AFolderThatCannotBeWrittenSaysSo) {
  std::ofstream(dir_ / "file") << "not a folder";
  SceneCache cache(dir_ / "file");
  const auto begun = cache.begin(files_, sha_);
  ASSERT_FALSE(begun.ok());
  EXPECT_NE(begun.error().find((dir_ / "file").string()), std::string::npos) << begun.error();
}

}  // namespace
}  // namespace optique::node
