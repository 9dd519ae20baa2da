// glTF scenes (common/scene_load/gltf.h): the shipped animated-cubes asset loads into
// the meshes, instances, lights and animated objects it describes, with poses that
// match hand-computed values, loop, and are pure functions of time; the content
// hash covers the file and every file it references; base colour textures are
// decoded and texture coordinates read; the textured torus as real exporters
// wrote it (beside its files, embedded, GLB, Draco) loads the same; files outside
// the folder, missing or truncated ones and unsupported required extensions are
// refused; what we cannot draw fails with a message that starts with the path and
// names the feature.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "image/texture_decode.h"
#include "scene/manifest.h"
#include "scene_load/gltf.h"
#include "scene_load/installation_scene.h"
#include "scratch.h"
#include "util/sha256.h"

namespace optique::scene {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kPi = std::numbers::pi;
constexpr double kTolerance = 1e-9;
const std::string kCubes = OPTIQUE_SOURCE_DIR "/configs/assets/animated-cubes.gltf";
const std::string kData = OPTIQUE_SOURCE_DIR "/tests/data/gltf/";
// The textured torus as obj2gltf and gltf-pipeline write it (scripts/make-gltf-assets.sh).
const std::string kTorus = OPTIQUE_SOURCE_DIR "/configs/assets/torus/";

using TempDir = optique::testing::ScratchDir;
using optique::testing::read_file;

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

json read_json(const std::string& path) { return json::parse(read_file(path)); }

void write_json(const std::string& path, const json& doc) { write_bytes(path, doc.dump(1)); }

LoadedGltf load_ok(const std::string& path) {
  auto loaded = load_gltf(path, image::decode_texture);
  EXPECT_TRUE(loaded.ok()) << (loaded.ok() ? "" : loaded.error());
  if (!loaded.ok()) return {};
  return std::move(loaded).value();
}

// Loads `path`, expecting an error that starts with the path and contains every
// one of `words`.
void expect_error(const std::string& path, std::initializer_list<std::string> words) {
  const auto loaded = load_gltf(path, image::decode_texture);
  ASSERT_FALSE(loaded.ok()) << path << " loaded";
  const std::string& message = loaded.error();
  EXPECT_EQ(message.rfind(path + ": ", 0), 0u) << message;
  for (const auto& word : words) EXPECT_NE(message.find(word), std::string::npos) << message;
}

// The animated-cubes document with `change` applied, written to `dir`.
std::string cubes_variant(const TempDir& dir, const std::function<void(json&)>& change) {
  json doc = read_json(kCubes);
  change(doc);
  const std::string path = dir.file("variant.gltf");
  write_json(path, doc);
  return path;
}

bool contains(const std::vector<std::string>& warnings, const std::string& word) {
  for (const auto& warning : warnings) {
    if (warning.find(word) != std::string::npos) return true;
  }
  return false;
}

void expect_near(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance = kTolerance) {
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(actual[i], expected[i], tolerance) << "component " << i;
}

// Equal as rotations: q and −q are the same.
void expect_rotation(const glm::dquat& actual, glm::dquat expected) {
  if (glm::dot(actual, expected) < 0.0) expected = -expected;
  EXPECT_NEAR(actual.w, expected.w, kTolerance);
  EXPECT_NEAR(actual.x, expected.x, kTolerance);
  EXPECT_NEAR(actual.y, expected.y, kTolerance);
  EXPECT_NEAR(actual.z, expected.z, kTolerance);
}

glm::dquat about(const glm::dvec3& axis, double degrees) { return glm::angleAxis(degrees * kPi / 180.0, axis); }

const AnimatedObject& object_named(const SceneDefinition& scene, const std::string& name) {
  for (const auto& object : scene.objects) {
    if (object.name == name) return object;
  }
  ADD_FAILURE() << "no object " << name;
  return scene.objects.front();
}

// --- the shipped asset

TEST(Gltf, AnimatedCubesHasItsContent) {
  const auto loaded = load_ok(kCubes);
  const auto& scene = loaded.scene;
  EXPECT_EQ(scene.name, "animated-cubes");
  EXPECT_TRUE(loaded.warnings.empty()) << loaded.warnings.front();
  ASSERT_EQ(scene.meshes.size(), 3u);
  for (const auto& mesh : scene.meshes) {
    EXPECT_EQ(mesh.vertices.size(), 24u);
    EXPECT_EQ(mesh.indices.size(), 36u);
  }
  ASSERT_EQ(scene.materials.size(), 3u);
  ASSERT_EQ(scene.instances.size(), 3u);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[0].id, 1u);
  EXPECT_EQ(scene.objects[1].id, 2u);
  EXPECT_EQ(scene.objects[0].name, "green-box");
  EXPECT_EQ(scene.objects[1].name, "blue-box");

  // The red box is static: translate · rotate · scale from its node.
  const auto& red = scene.instances[0];
  EXPECT_FALSE(red.object.has_value());
  const glm::dmat4 expected = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.45, 1.2, -0.5)) *
                              glm::mat4_cast(about({0, 1, 0}, 30.0)) * glm::scale(glm::dmat4(1.0), glm::dvec3(0.3));
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(red.transform[c][r], expected[c][r], 1e-12);
  }
  const auto& red_material = scene.materials[red.material];
  EXPECT_FLOAT_EQ(red_material.base_colour.r, 0.8f);
  EXPECT_FLOAT_EQ(red_material.base_colour.g, 0.15f);
  EXPECT_FLOAT_EQ(red_material.roughness, 0.4f);
  EXPECT_FLOAT_EQ(red_material.metallic, 0.0f);

  // The others ride on their objects.
  EXPECT_EQ(scene.instances[1].object, std::optional<std::uint32_t>(1));
  EXPECT_EQ(scene.instances[2].object, std::optional<std::uint32_t>(2));
  EXPECT_EQ(scene.instances[1].transform, glm::dmat4(1.0));
  const auto& blue_material = scene.materials[scene.instances[2].material];
  EXPECT_FLOAT_EQ(blue_material.metallic, 0.3f);
  EXPECT_FLOAT_EQ(blue_material.emissive.b, 0.05f);

  // Two point lights; glTF candela / 100.
  ASSERT_EQ(scene.lights.size(), 2u);
  expect_near(scene.lights[0].position, {-0.9, 2.3, 1.0});
  EXPECT_FLOAT_EQ(scene.lights[0].colour.g, 0.96f);
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 2.5f);
  expect_near(scene.lights[1].position, {1.1, 1.4, 0.7});
  EXPECT_FLOAT_EQ(scene.lights[1].intensity, 1.0f);
}

TEST(Gltf, GreenBoxPoseMatchesHandComputedValues) {
  const auto loaded = load_ok(kCubes);
  const auto& green = object_named(loaded.scene, "green-box");
  // Rotation keys every second, 0°, 90°, … 360° about y; translation keys at 0, 2,
  // 4 s with y = 1, 1.5, 1.
  const Pose early = green.pose_at(0.5);
  expect_near(early.position, {0.0, 1.125, -0.5});
  expect_rotation(early.rotation, about({0, 1, 0}, 45.0));
  expect_near(early.scale, glm::dvec3(0.3));

  const Pose late = green.pose_at(2.5);
  expect_near(late.position, {0.0, 1.375, -0.5});
  expect_rotation(late.rotation, about({0, 1, 0}, 225.0));
  expect_near(late.scale, glm::dvec3(0.3));
}

TEST(Gltf, ChildOfAnimatedPivotRidesOnItsWorldTransform) {
  const auto loaded = load_ok(kCubes);
  const auto& blue = object_named(loaded.scene, "blue-box");
  // The pivot at (0.45, 1.2, −0.5) turns about z 0° → 90° → 0° over 0, 1.5, 3 s;
  // the box sits 0.2 m above it.
  const double s60 = std::sin(kPi / 3.0);
  const Pose at_one = blue.pose_at(1.0);  // 60°
  expect_near(at_one.position, {0.45 - 0.2 * s60, 1.2 + 0.2 * 0.5, -0.5});
  expect_rotation(at_one.rotation, about({0, 0, 1}, 60.0));
  expect_near(at_one.scale, glm::dvec3(0.3));

  const Pose falling_back = blue.pose_at(2.25);  // 45°, on the way back
  expect_rotation(falling_back.rotation, about({0, 0, 1}, 45.0));

  // The swing ends at 3 s, the longest animation at 4 s: it holds its last key.
  const Pose after = blue.pose_at(3.5);
  expect_near(after.position, {0.45, 1.4, -0.5});
  expect_rotation(after.rotation, glm::dquat(1.0, 0.0, 0.0, 0.0));
}

TEST(Gltf, PosesLoopOverTheLongestAnimation) {
  const auto loaded = load_ok(kCubes);
  for (const auto& object : loaded.scene.objects) {
    EXPECT_EQ(object.pose_at(4.0), object.pose_at(0.0)) << object.name;
    EXPECT_EQ(object.pose_at(8.0), object.pose_at(0.0)) << object.name;
    EXPECT_EQ(object.pose_at(4.5), object.pose_at(0.5)) << object.name;
    EXPECT_EQ(object.pose_at(-3.5), object.pose_at(0.5)) << object.name;
    const Pose a = object.pose_at(401.3);
    const Pose b = object.pose_at(1.3);
    expect_near(a.position, b.position, 1e-9);
    expect_rotation(a.rotation, b.rotation);
  }
}

TEST(Gltf, PosesArePureDeterministicAndUnit) {
  const auto first = load_ok(kCubes);
  const auto second = load_ok(kCubes);
  ASSERT_EQ(first.scene.objects.size(), second.scene.objects.size());
  for (std::size_t i = 0; i < first.scene.objects.size(); ++i) {
    const auto& a = first.scene.objects[i];
    const auto& b = second.scene.objects[i];
    for (double t = -1.0; t < 9.0; t += 0.0625) {
      const Pose pose = a.pose_at(t);
      EXPECT_EQ(pose, a.pose_at(t));
      EXPECT_EQ(pose, b.pose_at(t));
      EXPECT_NEAR(glm::length(pose.rotation), 1.0, 1e-12);
      EXPECT_TRUE(std::isfinite(pose.position.x) && std::isfinite(pose.position.y) && std::isfinite(pose.position.z));
      EXPECT_TRUE(std::isfinite(pose.scale.x) && std::isfinite(pose.scale.y) && std::isfinite(pose.scale.z));
    }
    // Not a number in, a pose out all the same.
    EXPECT_EQ(a.pose_at(std::nan("")), a.pose_at(0.0));
  }
}

TEST(Gltf, ScaleAnimatedToZeroOnOneAxis) {
  TempDir dir;
  // The green box's translation keys, (0, 1 … 1.5, −0.5), as its scale too: x
  // collapses to 0 and z is negative; the pose must still give the world matrix.
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["animations"][0]["channels"].push_back({{"sampler", 1}, {"target", {{"node", 1}, {"path", "scale"}}}});
  });
  const auto loaded = load_ok(path);
  const auto& green = object_named(loaded.scene, "green-box");
  for (double t : {0.0, 0.5, 1.7, 2.5}) {
    const Pose pose = green.pose_at(t);
    const double y = t < 2.0 ? 1.0 + 0.25 * t : 1.5 - 0.25 * (t - 2.0);
    const glm::dmat4 expected = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, y, -0.5)) *
                                glm::mat4_cast(about({0, 1, 0}, 90.0 * t)) *
                                glm::scale(glm::dmat4(1.0), glm::dvec3(0.0, y, -0.5));
    const glm::dmat4 actual = model_matrix(pose);
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(actual[c][r], expected[c][r], 1e-9) << "t " << t;
    }
    EXPECT_NEAR(glm::length(pose.rotation), 1.0, 1e-12);
  }
}

// --- the content hash

TEST(Gltf, HashIsStableAndFollowsTheBytes) {
  const auto first = load_ok(kCubes);
  const auto second = load_ok(kCubes);
  EXPECT_EQ(first.content_sha256.size(), 64u);
  EXPECT_EQ(first.content_sha256, second.content_sha256);
  // The identity is the manifest's: one file, the glTF itself.
  ASSERT_EQ(first.manifest.files.size(), 1u);
  EXPECT_EQ(first.manifest.files[0].path, "animated-cubes.gltf");
  EXPECT_EQ(first.manifest.files[0].sha256, util::sha256_raw(read_file(kCubes)));
  EXPECT_EQ(first.content_sha256, manifest_sha256(first.manifest));
  ASSERT_EQ(first.files.size(), 1u);
  EXPECT_EQ(*first.files[0], read_file(kCubes));

  TempDir dir;
  std::string bytes = read_file(kCubes);
  const auto where = bytes.find("\"roughnessFactor\": 0.4");
  ASSERT_NE(where, std::string::npos);
  bytes[where + std::string("\"roughnessFactor\": 0.").size()] = '3';
  const std::string changed = dir.file("changed.gltf");
  write_bytes(changed, bytes);
  const auto modified = load_ok(changed);
  EXPECT_NE(modified.content_sha256, first.content_sha256);
}

TEST(Gltf, HashCoversSideBuffers) {
  TempDir dir;
  fs::copy_file(kData + "quad.gltf", dir.file("quad.gltf"));
  fs::copy_file(kData + "quad.bin", dir.file("quad.bin"));
  const auto original = load_ok(dir.file("quad.gltf"));
  ASSERT_EQ(original.manifest.files.size(), 2u);
  EXPECT_EQ(original.manifest.files[1].path, "quad.bin");
  EXPECT_EQ(original.manifest.files[1].sha256, util::sha256_raw(read_file(kData + "quad.bin")));
  EXPECT_EQ(original.content_sha256, manifest_sha256(original.manifest));

  std::string bin = read_file(dir.file("quad.bin"));
  bin[0] = static_cast<char>(bin[0] ^ 0x01);  // a tiny change to the first x coordinate
  write_bytes(dir.file("quad.bin"), bin);
  const auto changed = load_ok(dir.file("quad.gltf"));
  EXPECT_NE(changed.content_sha256, original.content_sha256);
}

// --- other files

TEST(Gltf, SideBufferFlatNormalsDefaultMaterialNoLight) {
  const auto loaded = load_ok(kData + "quad.gltf");
  const auto& scene = loaded.scene;
  ASSERT_EQ(scene.meshes.size(), 1u);
  const auto& mesh = scene.meshes[0];
  ASSERT_EQ(mesh.indices.size(), 6u);
  ASSERT_EQ(mesh.vertices.size(), 6u);  // flat: three vertices per triangle
  for (const auto& vertex : mesh.vertices) {
    EXPECT_FLOAT_EQ(vertex.normal.x, 0.0f);
    EXPECT_FLOAT_EQ(vertex.normal.y, 0.0f);
    EXPECT_FLOAT_EQ(vertex.normal.z, 1.0f);
  }
  ASSERT_EQ(scene.materials.size(), 1u);  // the default grey
  EXPECT_EQ(scene.materials[0].base_colour, Material{}.base_colour);
  ASSERT_EQ(scene.instances.size(), 1u);
  EXPECT_TRUE(scene.objects.empty());
  // holder: translate (0, 1, −1), scale 2; quad: a matrix translating x by 0.25.
  expect_near(glm::dvec3(scene.instances[0].transform[3]), {0.5, 1.0, -1.0});
  EXPECT_DOUBLE_EQ(scene.instances[0].transform[0][0], 2.0);
  // No lights in the file, and none added here (scene/default_lights.h does).
  EXPECT_TRUE(scene.lights.empty());
}

TEST(Gltf, BinaryGltfWithInterleavedVertices) {
  const auto loaded = load_ok(kData + "triangle.glb");
  const auto& scene = loaded.scene;
  ASSERT_EQ(scene.meshes.size(), 1u);
  ASSERT_EQ(scene.meshes[0].vertices.size(), 3u);
  EXPECT_EQ(scene.meshes[0].indices, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_FLOAT_EQ(scene.meshes[0].vertices[1].position.x, 1.0f);
  EXPECT_FLOAT_EQ(scene.meshes[0].vertices[2].normal.z, 1.0f);
  ASSERT_EQ(scene.lights.size(), 1u);
  expect_near(scene.lights[0].position, {0.0, 0.0, 3.0});
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 0.5f);
  EXPECT_EQ(scene.lights[0].colour, glm::vec3(1.0f));
  ASSERT_EQ(loaded.manifest.files.size(), 1u);
  EXPECT_EQ(loaded.manifest.files[0].sha256, util::sha256_raw(read_file(kData + "triangle.glb")));
}

TEST(Gltf, CubicSplineAndStepInterpolation) {
  const auto loaded = load_ok(kData + "interpolation.gltf");
  ASSERT_EQ(loaded.scene.objects.size(), 1u);
  const auto& mover = loaded.scene.objects[0];
  // Translation: x from 0 to 2 over 2 s, Hermite with zero tangents:
  // x(u) = 2·(3u² − 2u³).
  expect_near(mover.pose_at(0.5).position, {0.3125, 0.0, 0.0});
  expect_near(mover.pose_at(1.0).position, {1.0, 0.0, 0.0});
  expect_near(mover.pose_at(1.5).position, {1.6875, 0.0, 0.0});
  // Rotation steps from 0° to 90° about x at 1 s.
  expect_rotation(mover.pose_at(0.99).rotation, glm::dquat(1.0, 0.0, 0.0, 0.0));
  expect_rotation(mover.pose_at(1.0).rotation, about({1, 0, 0}, 90.0));
  expect_rotation(mover.pose_at(1.9).rotation, about({1, 0, 0}, 90.0));
  EXPECT_EQ(mover.pose_at(2.5), mover.pose_at(0.5));  // duration 2 s
}

TEST(Gltf, StripsAndFansBecomeTriangleLists) {
  TempDir dir;
  for (int mode : {5, 6}) {
    const auto path = cubes_variant(dir, [mode](json& doc) { doc["meshes"][0]["primitives"][0]["mode"] = mode; });
    const auto loaded = load_ok(path);
    ASSERT_EQ(loaded.scene.meshes.size(), 3u);
    EXPECT_EQ(loaded.scene.meshes[0].indices.size(), 3u * 34u) << "mode " << mode;  // 36 indices, 34 triangles
  }
}

TEST(Gltf, AnImageBesideTheFileIsReadAndSpotLightsAreIgnoredWithWarnings) {
  TempDir dir;
  fs::copy_file(kTorus + "torus.png", dir.file("checker.png"));
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["images"] = json::array({{{"uri", "checker.png"}}});
    doc["textures"] = json::array({{{"source", 0}}});
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    doc["extensions"]["KHR_lights_punctual"]["lights"][1] = {{"type", "spot"}, {"spot", json::object()}};
  });
  const auto loaded = load_ok(path);
  EXPECT_EQ(loaded.scene.textures.size(), 1u);
  EXPECT_EQ(loaded.manifest.files.size(), 2u);
  EXPECT_TRUE(contains(loaded.warnings, "spot lights are not supported"));
  EXPECT_EQ(loaded.scene.lights.size(), 1u);
  EXPECT_EQ(loaded.scene.instances.size(), 3u);
}

// --- base colour textures

const std::string kTexturedQuad = kData + "textured-quad.gltf";

// textured-quad.gltf's 2×2 RGB PNG, top row first, as RGBA (no alpha: 255).
const std::vector<std::uint8_t> kCheckerRgba{255, 128, 64,  255, 0,   255, 128, 255,   // top-left, top-right
                                             64,  0,   255, 255, 128, 64,  0,   255};  // bottom-left, bottom-right

// textured-quad.gltf with `change` applied, written to `dir` (its buffer and
// images are data URIs, so it needs nothing beside it).
std::string textured_variant(const TempDir& dir, const std::function<void(json&)>& change) {
  json doc = read_json(kTexturedQuad);
  change(doc);
  const std::string path = dir.file("textured.gltf");
  write_json(path, doc);
  return path;
}

void expect_checker(const SceneDefinition& scene) {
  ASSERT_EQ(scene.textures.size(), 1u);
  const Texture& texture = scene.textures[0];
  EXPECT_EQ(texture.width, 2);
  EXPECT_EQ(texture.height, 2);
  EXPECT_EQ(texture.rgba, kCheckerRgba);
  ASSERT_EQ(scene.materials.size(), 1u);
  ASSERT_TRUE(scene.materials[0].base_colour_texture.has_value());
  EXPECT_EQ(*scene.materials[0].base_colour_texture, 0u);
  EXPECT_EQ(scene.materials[0].base_colour, glm::vec3(1.0f));
}

void expect_quad_uvs(const SceneDefinition& scene) {
  ASSERT_EQ(scene.meshes.size(), 1u);
  const auto& vertices = scene.meshes[0].vertices;
  ASSERT_EQ(vertices.size(), 4u);
  // uv (0, 0) at the top-left corner, (1, 1) at the bottom-right.
  const glm::vec2 expected[] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}};
  const glm::vec3 corners[] = {{-1.0f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {-1.0f, -1.0f, 0.0f}};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(vertices[i].position, corners[i]) << "vertex " << i;
    EXPECT_EQ(vertices[i].uv, expected[i]) << "vertex " << i;
  }
}

TEST(Gltf, TexturedQuadHasItsTextureAndUvs) {
  const auto loaded = load_ok(kTexturedQuad);
  expect_checker(loaded.scene);
  expect_quad_uvs(loaded.scene);
  EXPECT_FALSE(contains(loaded.warnings, "baseColorTexture")) << ::testing::PrintToString(loaded.warnings);
}

TEST(Gltf, ImageInABufferView) {
  TempDir dir;
  const auto path = textured_variant(dir, [](json& doc) { doc["textures"][0]["source"] = 1; });
  const auto loaded = load_ok(path);
  expect_checker(loaded.scene);
}

TEST(Gltf, NormalizedUnsignedByteTexCoords) {
  TempDir dir;
  const auto path =
      textured_variant(dir, [](json& doc) { doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 3; });
  const auto loaded = load_ok(path);
  expect_quad_uvs(loaded.scene);
}

TEST(Gltf, SignedTexCoordsAreRefused) {
  TempDir dir;
  const auto path = textured_variant(dir, [](json& doc) {
    doc["accessors"][3]["componentType"] = 5120;  // BYTE
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 3;
  });
  expect_error(path, {"TEXCOORD_0", "BYTE"});
}

TEST(Gltf, SameImageInTwoMaterialsIsOneTexture) {
  TempDir dir;
  const auto path = textured_variant(dir, [](json& doc) {
    doc["materials"][1] = doc["materials"][0];
    doc["meshes"][0]["primitives"][1] = doc["meshes"][0]["primitives"][0];
    doc["meshes"][0]["primitives"][1]["material"] = 1;
  });
  const auto loaded = load_ok(path);
  ASSERT_EQ(loaded.scene.materials.size(), 2u);
  EXPECT_EQ(loaded.scene.textures.size(), 1u);
  EXPECT_EQ(loaded.scene.materials[1].base_colour_texture, loaded.scene.materials[0].base_colour_texture);
}

TEST(Gltf, UndecodableImageIsAWarningNotAnError) {
  TempDir dir;
  const auto path = textured_variant(dir, [](json& doc) {
    doc["images"][0]["uri"] = "data:image/png;base64,bm90IGEgcG5nIGF0IGFsbA==";  // "not a png at all"
  });
  const auto loaded = load_ok(path);
  EXPECT_TRUE(loaded.scene.textures.empty());
  ASSERT_EQ(loaded.scene.materials.size(), 1u);
  EXPECT_FALSE(loaded.scene.materials[0].base_colour_texture.has_value());
  EXPECT_TRUE(contains(loaded.warnings, "image 0 'checker' cannot be decoded"))
      << ::testing::PrintToString(loaded.warnings);
  expect_quad_uvs(loaded.scene);
}

TEST(Gltf, OtherTexCoordSetsAndTexturesAreIgnoredWithWarnings) {
  TempDir dir;
  const auto path = textured_variant(dir, [](json& doc) {
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = 1;
    doc["materials"][0]["normalTexture"] = {{"index", 0}};
  });
  const auto loaded = load_ok(path);
  EXPECT_TRUE(loaded.scene.textures.empty());
  EXPECT_FALSE(loaded.scene.materials[0].base_colour_texture.has_value());
  EXPECT_TRUE(contains(loaded.warnings, "TEXCOORD_1")) << ::testing::PrintToString(loaded.warnings);
  EXPECT_TRUE(contains(loaded.warnings, "ignored normalTexture")) << ::testing::PrintToString(loaded.warnings);
  EXPECT_FALSE(contains(loaded.warnings, "ignored baseColorTexture"));
}

// --- files as exporters write them: beside the glTF, in a GLB, compressed

// The torus's texture as decoded from its PNG.
Texture torus_texture() {
  const std::string png = read_file(kTorus + "torus.png");
  auto decoded = image::decode_texture(std::span(reinterpret_cast<const std::uint8_t*>(png.data()), png.size()), "");
  EXPECT_TRUE(decoded.ok());
  return decoded.ok() ? decoded.value() : Texture{};
}

// The torus as every form must give it: 8,192 triangles within its bounds
// (radii 0.35 and 0.15 about y), unit normals, texture coordinates in [0, 1],
// the texture whole.
void expect_torus(const LoadedGltf& loaded, double tolerance) {
  const SceneDefinition& scene = loaded.scene;
  ASSERT_EQ(scene.meshes.size(), 1u);
  const Mesh& mesh = scene.meshes[0];
  EXPECT_EQ(mesh.indices.size(), 3u * 8192u);
  glm::vec3 low(1e9f);
  glm::vec3 high(-1e9f);
  for (const Vertex& vertex : mesh.vertices) {
    low = glm::min(low, vertex.position);
    high = glm::max(high, vertex.position);
    EXPECT_NEAR(glm::length(vertex.normal), 1.0f, 1e-3f);
    EXPECT_GE(vertex.uv.x, -1e-3f);
    EXPECT_LE(vertex.uv.y, 1.0f + 1e-3f);
  }
  expect_near(glm::dvec3(low), {-0.5, -0.15, -0.5}, tolerance);
  expect_near(glm::dvec3(high), {0.5, 0.15, 0.5}, tolerance);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].rgba, torus_texture().rgba);
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].base_colour_texture, std::optional<std::uint32_t>(0u));
  EXPECT_TRUE(scene.lights.empty());
  EXPECT_TRUE(loaded.warnings.empty()) << ::testing::PrintToString(loaded.warnings);
}

TEST(Gltf, TorusWithItsBufferAndTextureBesideIt) {
  const auto loaded = load_ok(kTorus + "torus.gltf");
  expect_torus(loaded, 1e-6);
  ASSERT_EQ(loaded.manifest.files.size(), 3u);
  EXPECT_EQ(loaded.manifest.files[0].path, "torus.gltf");
  EXPECT_EQ(loaded.manifest.files[1].path, "torus.bin");
  EXPECT_EQ(loaded.manifest.files[2].path, "torus.png");
  EXPECT_EQ(loaded.manifest.files[2].sha256, util::sha256_raw(read_file(kTorus + "torus.png")));
  // The texture is part of the identity: another image, another scene.
  TempDir dir;
  for (const char* name : {"torus.gltf", "torus.bin", "torus.png"}) fs::copy_file(kTorus + name, dir.file(name));
  std::string png = read_file(dir.file("torus.png"));
  png.back() = static_cast<char>(png.back() ^ 1);  // the IEND chunk's CRC: still decodes
  write_bytes(dir.file("torus.png"), png);
  const auto changed = load_gltf(dir.file("torus.gltf"), {});
  ASSERT_TRUE(changed.ok()) << changed.error();
  EXPECT_NE(changed.value().content_sha256, loaded.content_sha256);
}

TEST(Gltf, TorusEmbeddedAndAsGlbAreTheSameMesh) {
  const auto separate = load_ok(kTorus + "torus.gltf");
  for (const char* form : {"torus-embedded.gltf", "torus.glb"}) {
    SCOPED_TRACE(form);
    const auto loaded = load_ok(kTorus + form);
    expect_torus(loaded, 1e-6);
    EXPECT_EQ(loaded.manifest.files.size(), 1u);
    ASSERT_EQ(loaded.scene.meshes.size(), 1u);
    ASSERT_EQ(loaded.scene.meshes[0].vertices.size(), separate.scene.meshes[0].vertices.size());
    for (std::size_t i = 0; i < loaded.scene.meshes[0].vertices.size(); ++i) {
      ASSERT_EQ(loaded.scene.meshes[0].vertices[i].position, separate.scene.meshes[0].vertices[i].position) << i;
      ASSERT_EQ(loaded.scene.meshes[0].vertices[i].uv, separate.scene.meshes[0].vertices[i].uv) << i;
    }
    EXPECT_EQ(loaded.scene.meshes[0].indices, separate.scene.meshes[0].indices);
  }
}

TEST(Gltf, DracoCompressedTorusDecodes) {
  const auto loaded = load_ok(kTorus + "torus-draco.glb");
  // gltf-pipeline quantizes positions to 11 bits over the 1 m box: 0.5 mm steps.
  expect_torus(loaded, 5e-4);
  // The decoded triangles cover the torus's surface as the original's do: the
  // same total area, to the quantization.
  const auto area = [](const Mesh& mesh) {
    double total = 0.0;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
      const glm::dvec3 a(mesh.vertices[mesh.indices[t]].position);
      const glm::dvec3 b(mesh.vertices[mesh.indices[t + 1]].position);
      const glm::dvec3 c(mesh.vertices[mesh.indices[t + 2]].position);
      total += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return total;
  };
  const auto plain = load_ok(kTorus + "torus.glb");
  EXPECT_NEAR(area(loaded.scene.meshes[0]), area(plain.scene.meshes[0]), 1e-3 * area(plain.scene.meshes[0]));
}

TEST(Gltf, ADracoExtensionThatIsNotAnObjectIsRefusedByName) {
  TempDir dir;
  fs::copy_file(kTorus + "torus.bin", dir.file("torus.bin"));
  fs::copy_file(kTorus + "torus.png", dir.file("torus.png"));
  json doc = read_json(kTorus + "torus.gltf");
  doc["meshes"][0]["primitives"][0]["extensions"] = {{"KHR_draco_mesh_compression", nullptr}};
  doc["meshes"][0]["primitives"][0]["indices"] = 4294967299.0;  // 2^32 + 3: no accessor's index
  write_json(dir.file("torus.gltf"), doc);
  expect_error(dir.file("torus.gltf"), {"mesh 0", "KHR_draco_mesh_compression"});
}

TEST(Gltf, AFileNameThatIsNotUtf8IsRefusedBeforeAnyNodeWouldBe) {
  TempDir dir;
  fs::copy_file(kTorus + "torus.bin", dir.file("torus.bin"));
  fs::copy_file(kTorus + "torus.png", dir.file("caf\xe9.png"));
  json doc = read_json(kTorus + "torus.gltf");
  doc["images"][0]["uri"] = "caf%E9.png";
  write_json(dir.file("torus.gltf"), doc);
  expect_error(dir.file("torus.gltf"), {"image 0", "not UTF-8"});
}

TEST(Gltf, CorruptDracoDataIsRefusedNamingThePrimitive) {
  TempDir dir;
  std::string glb = read_file(kTorus + "torus-draco.glb");
  // The binary chunk follows the JSON chunk: break the compressed mesh's start.
  const std::size_t json_length = static_cast<unsigned char>(glb[12]) | static_cast<unsigned char>(glb[13]) << 8;
  const std::size_t binary = 20 + json_length + 8;
  for (std::size_t i = binary; i < binary + 64 && i < glb.size(); ++i) glb[i] = static_cast<char>(0xA5);
  write_bytes(dir.file("broken.glb"), glb);
  expect_error(dir.file("broken.glb"), {"mesh 0", "primitive 0", "KHR_draco_mesh_compression", "cannot be decoded"});
}

// The separate torus copied to a fresh folder, with `change` applied to its JSON.
std::string torus_variant(const TempDir& dir, const std::function<void(json&)>& change) {
  for (const char* name : {"torus.bin", "torus.png"}) fs::copy_file(kTorus + name, dir.file(name));
  json doc = read_json(kTorus + "torus.gltf");
  change(doc);
  const std::string path = dir.file("torus.gltf");
  write_json(path, doc);
  return path;
}

TEST(Gltf, UrisThatLeaveTheFolderAreRefusedByName) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"../torus.bin", "leaves the scene's folder ('..')"},
      {"sub/../../torus.bin", "leaves the scene's folder ('..')"},
      {"%2E%2E/torus.bin", "leaves the scene's folder ('..')"},
      {"/etc/passwd", "is an absolute path"},
      {"file:///etc/passwd", "names a scheme ('file:')"},
      {"https://example.com/torus.bin", "names a scheme ('https:')"},
      {"C:/models/torus.bin", "names a scheme ('C:')"},
      {"torus.bin?v=2", "query or a fragment"},
      {"torus%2", "'%' that is not followed by two hex digits"},
  };
  for (const auto& [uri, reason] : cases) {
    SCOPED_TRACE(uri);
    TempDir dir;
    const auto path = torus_variant(dir, [u = uri](json& doc) { doc["buffers"][0]["uri"] = u; });
    expect_error(path, {"buffer 0", reason});
  }
}

TEST(Gltf, ALinkOutOfTheFolderIsRefused) {
  TempDir outside;
  TempDir dir;
  fs::copy_file(kTorus + "torus.png", outside.file("secret.png"));
  const auto path = torus_variant(dir, [](json& doc) { doc["images"][0]["uri"] = "link.png"; });
  fs::create_symlink(outside.file("secret.png"), dir.file("link.png"));
  expect_error(path, {"image 0 'link.png'", "a link to a file outside the glTF's folder"});
}

TEST(Gltf, AFileInASubfolderAndAnEscapedNameAreRead) {
  TempDir dir;
  const auto path = torus_variant(dir, [](json& doc) { doc["images"][0]["uri"] = "maps/the%20torus.png"; });
  fs::create_directory(dir.file("maps"));
  fs::copy_file(kTorus + "torus.png", dir.file("maps/the torus.png"));
  const auto loaded = load_ok(path);
  ASSERT_EQ(loaded.manifest.files.size(), 3u);
  EXPECT_EQ(loaded.manifest.files[2].path, "maps/the torus.png");
  EXPECT_EQ(loaded.scene.textures.size(), 1u);
}

TEST(Gltf, EveryMissingFileIsNamedAtOnce) {
  TempDir dir;
  const auto path = torus_variant(dir, [](json& doc) {
    doc["buffers"][0]["uri"] = "gone.bin";
    doc["images"][0]["uri"] = "gone.png";
  });
  expect_error(path, {"buffer 0 'gone.bin': missing", "image 0 'gone.png': missing", dir.file("gone.png")});
}

TEST(Gltf, ATruncatedBufferIsRefused) {
  TempDir dir;
  const auto path = torus_variant(dir, [](json&) {});
  write_bytes(dir.file("torus.bin"), read_file(dir.file("torus.bin")).substr(0, 1000));
  expect_error(path, {"buffer 0 'torus.bin' is truncated: 1000 bytes where its byteLength says 184352"});
}

// A buffer view that runs past its buffer (the buffer itself whole): refused
// where the view is read, naming it, never read beyond the buffer.
TEST(Gltf, ABufferViewPastItsBufferIsRefused) {
  TempDir dir;
  const auto path = torus_variant(dir, [](json& doc) {
    auto& view = doc["bufferViews"][0];
    view["byteOffset"] = view.value("byteOffset", 0) + 184352 - 8;  // 8 bytes before the end of the buffer
  });
  expect_error(path, {"buffer view 0", "is out of range of buffer 0 (184352 bytes)"});
}

TEST(Gltf, ATruncatedGlbIsRefused) {
  TempDir dir;
  const std::string glb = read_file(kTorus + "torus.glb");
  write_bytes(dir.file("cut.glb"), glb.substr(0, glb.size() / 2));
  expect_error(dir.file("cut.glb"), {"malformed GLB", "truncated"});
}

// The GLB's chunks checked one by one, past a header that is whole: a BIN
// chunk that says it runs 4 bytes past the file, and one that is whole but
// shorter than the buffer's byteLength.
TEST(Gltf, AGlbChunkPastTheEndOrShorterThanItsBufferIsRefused) {
  TempDir dir;
  const std::string glb = read_file(kTorus + "torus.glb");
  const auto u32 = [](const std::string& bytes, std::size_t at) {
    return static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at])) |
           static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 8 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 2])) << 16 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 3])) << 24;
  };
  const auto put = [](std::string& bytes, std::size_t at, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>(value >> (8 * i));
  };
  const std::size_t bin = 12 + 8 + u32(glb, 12);  // the BIN chunk's header
  ASSERT_LT(bin + 8, glb.size());
  ASSERT_EQ(u32(glb, 8), glb.size());

  std::string over = glb;
  put(over, bin, u32(glb, bin) + 4);
  write_bytes(dir.file("over.glb"), over);
  expect_error(dir.file("over.glb"),
               {"malformed GLB", "a chunk at byte " + std::to_string(bin) + " runs past the end"});

  std::string shorter = glb.substr(0, glb.size() - 8);
  put(shorter, 8, static_cast<std::uint32_t>(shorter.size()));
  put(shorter, bin, u32(glb, bin) - 8);
  write_bytes(dir.file("short.glb"), shorter);
  expect_error(dir.file("short.glb"), {"buffer 0 (the GLB's binary chunk) is truncated"});
}

TEST(Gltf, UnsupportedRequiredExtensionsAreListedBeforeAnythingElse) {
  TempDir dir;
  const auto path = torus_variant(dir, [](json& doc) {
    doc["extensionsRequired"] =
        json::array({"EXT_meshopt_compression", "KHR_draco_mesh_compression", "KHR_texture_basisu"});
    doc["buffers"][0]["uri"] = "gone.bin";  // not looked at: the extensions decide first
    doc["accessors"][0]["bufferView"] = 99;
  });
  expect_error(path, {"requires extensions that optique cannot draw: EXT_meshopt_compression, KHR_texture_basisu ("});
  const auto message = load_gltf(path, {}).error();
  EXPECT_EQ(message.find("gone.bin"), std::string::npos) << message;
  EXPECT_EQ(message.find("KHR_draco_mesh_compression,"), std::string::npos) << message;
}

// --- errors

TEST(Gltf, MissingFile) { expect_error(kData + "no-such.gltf", {"no such file"}); }

TEST(Gltf, MalformedJson) {
  TempDir dir;
  const std::string path = dir.file("broken.gltf");
  const std::string bytes = read_file(kCubes);
  write_bytes(path, bytes.substr(0, bytes.size() / 2));
  expect_error(path, {"malformed glTF"});
}

TEST(Gltf, MissingBufferFile) {
  TempDir dir;
  fs::copy_file(kData + "quad.gltf", dir.file("quad.gltf"));
  expect_error(dir.file("quad.gltf"), {"buffer 0 'quad.bin': missing", dir.file("quad.bin")});
}

TEST(Gltf, SkinsAreRefused) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["skins"] = json::array({{{"joints", json::array({0})}}});
    doc["nodes"][1]["skin"] = 0;
  });
  expect_error(path, {"skinned meshes are not supported"});
}

TEST(Gltf, MorphTargetWeightsAreRefused) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["animations"][0]["channels"].push_back({{"sampler", 1}, {"target", {{"node", 1}, {"path", "weights"}}}});
  });
  expect_error(path, {"morph targets are not supported"});
}

TEST(Gltf, UnsupportedRequiredExtensionIsRefused) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["extensionsUsed"].push_back("EXT_meshopt_compression");
    doc["extensionsRequired"] = json::array({"KHR_lights_punctual", "EXT_meshopt_compression"});
  });
  expect_error(path, {"requires an extension that optique cannot draw: EXT_meshopt_compression",
                      "it reads KHR_lights_punctual"});
}

TEST(Gltf, AccessorOutOfRange) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) { doc["accessors"][0]["count"] = 1000; });
  expect_error(path, {"accessor 0", "POSITION", "out of range"});
}

TEST(Gltf, IndexOutOfRange) {
  TempDir dir;
  json doc = read_json(kData + "quad.gltf");
  doc["accessors"][0]["count"] = 2;
  doc["accessors"][0]["min"] = {-0.5, -0.5, 0};
  doc["accessors"][0]["max"] = {0.5, -0.5, 0};
  write_json(dir.file("quad.gltf"), doc);
  fs::copy_file(kData + "quad.bin", dir.file("quad.bin"));
  expect_error(dir.file("quad.gltf"), {"index 2", "out of range"});
}

TEST(Gltf, NonFloatPositionsNameTheAccessor) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) { doc["accessors"][0]["componentType"] = 5123; });
  expect_error(path, {"accessor 0", "POSITION", "UNSIGNED_SHORT", "FLOAT only"});
}

TEST(Gltf, PointsAreRefused) {
  TempDir dir;
  const auto path = cubes_variant(dir, [](json& doc) { doc["meshes"][1]["primitives"][0]["mode"] = 0; });
  expect_error(path, {"POINTS is not supported"});
}

TEST(Gltf, ShearOnAnAnimatedNodeIsRefused) {
  TempDir dir;
  // A non-uniformly scaled parent above the turning pivot.
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["nodes"].push_back({{"name", "stretch"}, {"scale", {1.0, 2.0, 1.0}}, {"children", {2}}});
    doc["scenes"][0]["nodes"] = {0, 1, 6, 4, 5};
  });
  expect_error(path, {"blue-box", "shear"});
}

TEST(Gltf, NonFiniteWorldTransformsAreRefused) {
  TempDir dir;
  // Every number is finite in JSON, but a parent scaled by 1e308 above a child
  // translated by 1e308 overflows.
  const auto path = cubes_variant(dir, [](json& doc) {
    doc["nodes"].push_back({{"name", "huge"}, {"scale", {1e308, 1e308, 1e308}}, {"children", {0}}});
    doc["nodes"][0]["translation"] = {1e308, 0.0, 0.0};
    doc["scenes"][0]["nodes"] = {6, 1, 2, 4, 5};
  });
  expect_error(path, {"red-box", "not finite"});
}

// An asset an application loads: named by its id, its lights dropped (the
// installation's light it), and refused when its files are not those of the
// identity it was loaded with (a journal's, a master's offer).
TEST(Gltf, AnAssetIsNamedUnlitAndCheckedAgainstItsIdentity) {
  const std::string torus = std::string(OPTIQUE_SOURCE_DIR) + "/configs/assets/torus/torus.glb";
  auto loaded = config::load_asset("ring", torus, {});
  ASSERT_TRUE(loaded) << loaded.error();
  EXPECT_EQ(loaded.value().definition.asset_id, "ring");
  EXPECT_TRUE(loaded.value().definition.lights.empty());
  EXPECT_TRUE(config::load_asset("ring", torus, {}, loaded.value().content_sha256));
  auto changed = config::load_asset("ring", torus, {}, std::string(64, 'a'));
  ASSERT_FALSE(changed);
  EXPECT_NE(changed.error().find("is not the asset 'ring' it was loaded as: its files have changed"), std::string::npos)
      << changed.error();
}

}  // namespace
}  // namespace optique::scene
