// The files a scene is made of (scene/relative_path.h, scene/manifest.h), the
// default lights (scene/default_lights.h), and the shipped glTF assets' record
// from the Khronos validator (configs/assets/gltf-validation.jsonl, written by
// scripts/make-gltf-assets.sh): every asset listed, unchanged since, without error.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "scene/default_lights.h"
#include "scene_load/load_scene.h"
#include "scene/manifest.h"
#include "scene/meshes.h"
#include "scene/relative_path.h"
#include "scratch.h"
#include "util/sha256.h"

namespace optique::scene {
namespace {

namespace fs = std::filesystem;

TEST(RelativePath, PlainPathsAreKeptInTheirPlainForm) {
  EXPECT_EQ(checked_relative_path("torus.bin").value(), "torus.bin");
  EXPECT_EQ(checked_relative_path("./maps//wood.png").value(), "maps/wood.png");
  EXPECT_EQ(relative_file_of_uri("maps/the%20wood.png").value(), "maps/the wood.png");
  EXPECT_EQ(relative_file_of_uri("a+b.bin").value(), "a+b.bin");
  EXPECT_EQ(relative_file_of_uri("caf%C3%A9.png").value(), "caf\xc3\xa9.png");  // UTF-8, escaped
}

TEST(RelativePath, WhatLeavesTheFolderIsRefusedSayingWhy) {
  const std::map<std::string, std::string> paths{
      {"", "is empty"},
      {"..", "leaves the scene's folder"},
      {"a/../../b", "leaves the scene's folder"},
      {"/etc/passwd", "is an absolute path"},
      {"a\\..\\b", "backslash"},
      {std::string("a\0b", 3), "NUL"},
      {".", "names the folder itself"},
      {"caf\xe9.png", "not UTF-8"},       // Latin-1
      {"a\xc0\xaf.png", "not UTF-8"},     // an overlong '/'
      {"\xed\xa0\x80.png", "not UTF-8"},  // a surrogate
      {"x\xf0\x9f\x98", "not UTF-8"},     // cut short
  };
  for (const auto& [path, reason] : paths) {
    const auto checked = checked_relative_path(path);
    ASSERT_FALSE(checked.ok()) << path;
    EXPECT_NE(checked.error().find(reason), std::string::npos) << path << ": " << checked.error();
  }
  const std::map<std::string, std::string> uris{
      {"http://host/a.bin", "names a scheme ('http:')"},
      {"%2e%2e/a.bin", "leaves the scene's folder"},
      {"%2Fetc/passwd", "is an absolute path"},
      {"a.bin#x", "query or a fragment"},
      {"a%zz.bin", "two hex digits"},
      {"a%2", "two hex digits"},
      {"caf%E9.png", "not UTF-8"},
  };
  for (const auto& [uri, reason] : uris) {
    const auto checked = relative_file_of_uri(uri);
    ASSERT_FALSE(checked.ok()) << uri;
    EXPECT_NE(checked.error().find(reason), std::string::npos) << uri << ": " << checked.error();
  }
  EXPECT_TRUE(is_data_uri("data:application/octet-stream;base64,AAAA"));
  EXPECT_FALSE(is_data_uri("database.bin"));
}

TEST(Manifest, ChunksCoverTheFileAndTheirDigestsAreTheirBytes) {
  std::string bytes(10000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  const SceneFile file = describe_file("a.bin", bytes, 4096);
  EXPECT_EQ(file.size, 10000u);
  EXPECT_EQ(file.chunks(4096), 3u);
  EXPECT_EQ(file.sha256, util::sha256_raw(bytes));
  EXPECT_EQ(file.chunk_digest(0), util::sha256_raw(bytes.substr(0, 4096)));
  EXPECT_EQ(file.chunk_digest(2), util::sha256_raw(bytes.substr(8192)));
  SceneManifest manifest{4096, {file}};
  EXPECT_EQ(manifest.chunk_length(0, 2), 10000u - 8192u);
  EXPECT_EQ(manifest.total_bytes(), 10000u);
  EXPECT_TRUE(check_manifest(manifest, {20000, 10}).ok());
  const SceneFile empty = describe_file("empty.bin", "", 4096);
  EXPECT_EQ(empty.chunks(4096), 0u);
  EXPECT_TRUE(empty.chunk_sha256.empty());
}

TEST(Manifest, TheIdentityFollowsEveryPathSizeDigestAndTheChunkSize) {
  const SceneManifest base{4096, {describe_file("s.gltf", "{}", 4096), describe_file("a.bin", "abc", 4096)}};
  const std::string identity = manifest_sha256(base);
  EXPECT_EQ(identity.size(), 64u);
  EXPECT_EQ(manifest_sha256(base), identity);
  std::vector<SceneManifest> changed(5, base);
  changed[0].files[1].path = "b.bin";
  changed[1].files[1] = describe_file("a.bin", "abd", 4096);
  changed[2].chunk_bytes = 8192;
  std::swap(changed[3].files[0], changed[3].files[1]);
  // A chunk's digest alone: nodes check each chunk against it, so a manifest
  // whose identity did not cover it could send them spoilt chunks as good.
  changed[4].files[1].chunk_sha256[0] = static_cast<char>(changed[4].files[1].chunk_sha256[0] ^ 1);
  for (const auto& manifest : changed) EXPECT_NE(manifest_sha256(manifest), identity);
}

TEST(Manifest, APeersManifestIsCheckedBeforeAnythingIsFetched) {
  const SceneManifest good{4096, {describe_file("s.gltf", "{}", 4096), describe_file("maps/a.png", "abc", 4096)}};
  const ManifestLimits limits{1000, 10};
  EXPECT_TRUE(check_manifest(good, limits).ok());
  const auto refused = [&](SceneManifest manifest, const std::string& reason, ManifestLimits with) {
    const auto checked = check_manifest(manifest, with);
    ASSERT_FALSE(checked.ok()) << reason;
    EXPECT_NE(checked.error().find(reason), std::string::npos) << checked.error();
  };
  SceneManifest m = good;
  m.files[1].path = "../a.png";
  refused(m, "leaves the scene's folder", limits);
  m = good;
  m.files[1].path = "maps//a.png";
  refused(m, "not written in its plain form", limits);
  m = good;
  m.files[1].path = "s.gltf";
  refused(m, "listed twice", limits);
  m = good;
  m.files[1].sha256 = "short";
  refused(m, "not 32 bytes", limits);
  m = good;
  m.files[1].size = 5000;  // two chunks, one digest
  refused(m, "larger than the 1000 bytes", limits);
  {
    // Every file within the limit, all of them together not.
    SceneManifest two{
        4096,
        {describe_file("s.gltf", std::string(600, '{'), 4096), describe_file("a.bin", std::string(600, 'a'), 4096)}};
    refused(two, "larger than the 1000 bytes", limits);
  }
  refused(m, "1 chunk digests for 2 chunks", {100000, 10});
  m = good;
  m.chunk_bytes = 16;
  refused(m, "chunk size 16", limits);
  refused(good, "2 files, more than the 1", {1000, 1});
  refused(SceneManifest{}, "lists no file", limits);
}

TEST(DefaultLights, AKeyAFillAndARimScaledToTheSceneAsTheViewerSeesIt) {
  SceneDefinition scene;
  scene.meshes.push_back(make_box({2.0f, 2.0f, 2.0f}));
  scene.materials.emplace_back();
  Instance instance;
  instance.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 1.0, -3.0));
  scene.instances.push_back(instance);
  const glm::dvec3 viewer(0.0, 1.0, 2.0);
  const std::string said = add_default_lights(scene, viewer);
  EXPECT_NE(said.find("key, a fill and a rim"), std::string::npos) << said;
  ASSERT_EQ(scene.lights.size(), 3u);
  const glm::dvec3 centre(0.0, 1.0, -3.0);
  const double radius = std::sqrt(3.0);
  const glm::dvec3 forward = glm::normalize(centre - viewer);
  for (const PointLight& light : scene.lights) {
    EXPECT_NEAR(glm::length(light.position - centre), 5.0 * radius, 1e-9);
    EXPECT_GT(light.intensity, 0.0f);
  }
  // Key and fill from the viewer's side, the key above and left, the fill right;
  // the rim from behind.
  EXPECT_LT(glm::dot(scene.lights[0].position - centre, forward), 0.0);
  EXPECT_GT(scene.lights[0].position.y, centre.y);
  EXPECT_LT(scene.lights[0].position.x, centre.x);
  EXPECT_LT(glm::dot(scene.lights[1].position - centre, forward), 0.0);
  EXPECT_GT(scene.lights[1].position.x, centre.x);
  EXPECT_GT(glm::dot(scene.lights[2].position - centre, forward), 0.0);
  // The key gives a surface facing it 0.85 π of irradiance at the centre.
  const double r = glm::length(scene.lights[0].position - centre);
  EXPECT_NEAR(scene.lights[0].intensity / (r * r), 0.85 * 3.14159265, 1e-5);
  EXPECT_GE(scene.ambient.x, 0.08f);
}

TEST(DefaultLights, AnEmptySceneAndAViewerAtTheCentreStillGetFiniteLights) {
  SceneDefinition scene;
  (void)add_default_lights(scene, glm::dvec3(0.0));
  ASSERT_EQ(scene.lights.size(), 3u);
  for (const PointLight& light : scene.lights) {
    EXPECT_TRUE(std::isfinite(light.position.x) && std::isfinite(light.position.y) && std::isfinite(light.position.z));
  }
}

// --- the shipped glTF assets, as the Khronos validator saw them

using optique::testing::read_file;

TEST(ShippedAssets, EveryGltfAssetPassedTheKhronosValidatorAsItIsNow) {
  const fs::path root = OPTIQUE_SOURCE_DIR;
  std::map<std::string, nlohmann::json> reports;
  std::ifstream in(root / "configs/assets/gltf-validation.jsonl");
  ASSERT_TRUE(in) << "configs/assets/gltf-validation.jsonl is missing: run scripts/make-gltf-assets.sh";
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    const auto report = nlohmann::json::parse(line);
    reports[report.at("file").get<std::string>()] = report;
  }
  std::set<std::string> assets;
  for (const auto& entry : fs::recursive_directory_iterator(root / "configs/assets")) {
    const std::string extension = entry.path().extension().string();
    if (extension == ".gltf" || extension == ".glb") assets.insert(entry.path().lexically_relative(root).string());
  }
  ASSERT_FALSE(assets.empty());
  for (const std::string& asset : assets) {
    SCOPED_TRACE(asset);
    const auto found = reports.find(asset);
    ASSERT_NE(found, reports.end()) << "not validated: run scripts/make-gltf-assets.sh";
    const nlohmann::json& report = found->second;
    EXPECT_EQ(report.at("errors").get<int>(), 0) << report.dump();
    EXPECT_EQ(report.at("warnings").get<int>(), 0) << report.dump();
    EXPECT_EQ(report.at("sha256").get<std::string>(), util::sha256_hex(read_file(root / asset)))
        << "changed since it was validated: run scripts/make-gltf-assets.sh";
    for (const auto& [uri, digest] : report.at("resources").items()) {
      EXPECT_EQ(digest.get<std::string>(), util::sha256_hex(read_file((root / asset).parent_path() / uri)))
          << uri << " changed since it was validated: run scripts/make-gltf-assets.sh";
    }
  }
}

}  // namespace
}  // namespace optique::scene

namespace optique::scene {
namespace {

// How a glTF is lit is said either way, and as a note, not a warning: an
// export without lights is the usual case, not a fault.
TEST(DefaultLights, HowAFileIsLitIsANoteEitherWay) {
  const glm::dvec3 viewer(0.0, 1.6, 3.0);
  auto unlit = load_scene("", OPTIQUE_SOURCE_DIR "/configs/assets/torus/torus.gltf", {}, viewer);
  ASSERT_TRUE(unlit) << unlit.error();
  // After the note of its size and where it stands (test_placement.cpp).
  ASSERT_EQ(unlit.value().notes.size(), 2u);
  EXPECT_NE(unlit.value().notes.back().find("a key, a fill and a rim light"), std::string::npos);
  for (const std::string& w : unlit.value().warnings) EXPECT_EQ(w.find("key, a fill"), std::string::npos) << w;
  auto lit = load_scene("", OPTIQUE_SOURCE_DIR "/configs/assets/animated-cubes.gltf", {}, viewer);
  ASSERT_TRUE(lit) << lit.error();
  ASSERT_EQ(lit.value().notes.size(), 2u);
  EXPECT_NE(lit.value().notes.back().find("lit by the file's 2 point light(s)"), std::string::npos)
      << lit.value().notes.back();
}

}  // namespace
}  // namespace optique::scene
