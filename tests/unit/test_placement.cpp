// Where a model stands in the room (scene/placement.h, config scene.placement,
// scene_load/load_scene.h): a glTF file is drawn at its own size at the
// origin unless it is placed.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <numbers>

#include <glm/gtc/matrix_access.hpp>
#include <glm/gtc/quaternion.hpp>

#include "config/load.h"
#include "scene/placement.h"
#include "scene_load/installation_scene.h"
#include "scratch.h"

namespace optique::scene {
namespace {

// A glTF box from `low` to `high` (file units), written as box.gltf and box.bin in `dir`.
std::string write_box(const testing::ScratchDir& dir, const glm::vec3& low, const glm::vec3& high) {
  std::array<float, 24> positions{};
  for (int corner = 0; corner < 8; ++corner) {
    positions[3 * corner] = (corner & 1) != 0 ? high.x : low.x;
    positions[3 * corner + 1] = (corner & 2) != 0 ? high.y : low.y;
    positions[3 * corner + 2] = (corner & 4) != 0 ? high.z : low.z;
  }
  const std::array<std::uint16_t, 36> indices{0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                              2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
  {
    std::ofstream bin(dir.file("box.bin"), std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions.data()), sizeof(positions));
    bin.write(reinterpret_cast<const char*>(indices.data()), sizeof(indices));
  }
  const auto v = [](const glm::vec3& p) {
    return "[" + std::to_string(p.x) + "," + std::to_string(p.y) + "," + std::to_string(p.z) + "]";
  };
  std::ofstream(dir.file("box.gltf"))
      << R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      << R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
      << R"("buffers":[{"uri":"box.bin","byteLength":168}],)"
      << R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":96},{"buffer":0,"byteOffset":96,"byteLength":72}],)"
      << R"("accessors":[{"bufferView":0,"componentType":5126,"count":8,"type":"VEC3","min":)" << v(low) << R"(,"max":)"
      << v(high) << R"(},{"bufferView":1,"componentType":5123,"count":36,"type":"SCALAR"}]})";
  return dir.file("box.gltf");
}

// Whether every corner of `box`, seen from `eye`, lands on the screen (its
// frame's metres, with `margin` to spare at each edge); `why` says where one
// did not.
bool on_screen(const Box& box, const glm::dvec3& eye, const config::Screen& screen, double margin, std::string& why) {
  const glm::dvec3 normal = glm::cross(screen.right, screen.up);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::dvec3 p{(corner & 1) != 0 ? box.high.x : box.low.x, (corner & 2) != 0 ? box.high.y : box.low.y,
                       (corner & 4) != 0 ? box.high.z : box.low.z};
    const double t = glm::dot(screen.origin - eye, normal) / glm::dot(p - eye, normal);
    const glm::dvec3 on = eye + t * (p - eye) - screen.origin;
    const double x = glm::dot(on, screen.right);
    const double y = glm::dot(on, screen.up);
    if (!(t > 0.0 && x >= margin && x <= screen.width - margin && y >= margin && y <= screen.height - margin)) {
      why = "corner " + std::to_string(corner) + " lands at (" + std::to_string(x) + ", " + std::to_string(y) +
            ") m on a " + std::to_string(screen.width) + " × " + std::to_string(screen.height) + " m screen" +
            (t > 0.0 ? "" : ", behind the eye");
      return false;
    }
  }
  return true;
}

// The issue's bar: a model of 100 units and one of 1 cm, fitted into a box
// behind a shipped wall, are each wholly on it as the viewer sees it, as
// large as the box allows and centred in it; unplaced, the large one is not.
TEST(Placement, FitPutsAHundredUnitModelAndACentimetreOneWhollyOnAShippedWall) {
  auto loaded = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/gltf-torus.json");
  ASSERT_TRUE(loaded) << loaded.error();
  config::Installation installation = loaded.value().installation;
  const config::Screen& screen = installation.screens.front();
  const glm::dvec3 eye = installation.viewer.eye_at(0.0);
  const glm::dvec3 centre =
      screen.point({0.5 * screen.width, 0.5 * screen.height}) - 0.3 * glm::cross(screen.right, screen.up);
  const glm::dvec3 room{0.6 * screen.width, 0.6 * screen.height, 0.4};
  for (const float size : {100.0f, 0.01f}) {
    const testing::ScratchDir dir("optique-placement");
    installation.scene.gltf = write_box(dir, {size, 2 * size, -3 * size}, {2 * size, 2.5f * size, -2 * size});
    installation.scene.placement.reset();
    auto unplaced = config::load_scene(installation, {});
    ASSERT_TRUE(unplaced) << unplaced.error();
    const std::optional<Box> as_made = world_bounds(unplaced.value().definition);
    ASSERT_TRUE(as_made);
    EXPECT_NEAR(as_made->size().x, size, 1e-6 * size);
    std::string why;
    if (size > 1.0f) {
      EXPECT_FALSE(on_screen(*as_made, eye, screen, 0.0, why)) << "unplaced, 100 units are off the wall";
    }

    Placement placement;
    placement.fit = Placement::Fit{centre, room};
    installation.scene.placement = placement;
    auto placed = config::load_scene(installation, {});
    ASSERT_TRUE(placed) << placed.error();
    const std::optional<Box> bounds = world_bounds(placed.value().definition);
    ASSERT_TRUE(bounds);
    const std::string what = std::to_string(size) + " units";
    // The model is 1 × 0.5 × 1 of its units, the box 1.2 × 0.675 × 0.4 m:
    // the depth is the tightest.
    const double scale = std::min({room.x / size, room.y / (0.5 * size), room.z / size});
    EXPECT_NEAR(bounds->size().x, scale * size, 1e-6) << what;
    EXPECT_NEAR(bounds->size().y, scale * 0.5 * size, 1e-6) << what;
    EXPECT_NEAR(glm::length(bounds->centre() - centre), 0.0, 1e-6) << what;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(bounds->size()[axis], room[axis] + 1e-9) << what << ", axis " << axis;
    }
    EXPECT_TRUE(on_screen(*bounds, eye, screen, 0.01, why)) << what << ": " << why;
    bool noted = false;
    for (const std::string& note : placed.value().notes)
      noted = noted || note.find("placed to fit") != std::string::npos;
    EXPECT_TRUE(noted) << what << ": the log and check-config say where it stands";
  }
}

// Turned, a model is fitted by its own bounds as turned, not by its box
// turned: the torus turned 45° about x touches the box's tightest side.
TEST(Placement, ATurnedModelIsFittedAsLargeAsItsTurnedShapeAllows) {
  auto loaded = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/gltf-torus.json");
  ASSERT_TRUE(loaded) << loaded.error();
  config::Installation installation = loaded.value().installation;
  Placement placement;
  placement.rotation = glm::angleAxis(std::numbers::pi / 4, glm::dvec3(1.0, 0.0, 0.0));
  placement.fit = Placement::Fit{{0.0, 0.0, -0.5}, {1.6, 1.0, 0.8}};
  installation.scene.placement = placement;
  auto placed = config::load_scene(installation, {});
  ASSERT_TRUE(placed) << placed.error();
  const std::optional<Box> bounds = world_bounds(placed.value().definition);
  ASSERT_TRUE(bounds);
  double fullest = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(bounds->size()[axis], placement.fit->size[axis] + 1e-9) << "axis " << axis;
    fullest = std::max(fullest, bounds->size()[axis] / placement.fit->size[axis]);
  }
  EXPECT_NEAR(fullest, 1.0, 1e-9) << "as large as the box allows";
  EXPECT_NEAR(glm::length(bounds->centre() - placement.fit->centre), 0.0, 1e-9);
}

// A model placed where the viewer stands is reported (a room around the
// viewer is right in a CAVE; a model to be seen from outside is not).
TEST(Placement, AModelAroundTheViewerIsReported) {
  auto loaded = config::load_installation(std::string(OPTIQUE_SOURCE_DIR) + "/configs/gltf-torus.json");
  ASSERT_TRUE(loaded) << loaded.error();
  config::Installation installation = loaded.value().installation;
  const glm::dvec3 eye = installation.viewer.eye_at(0.0);
  const testing::ScratchDir dir("optique-placement");
  installation.scene.gltf = write_box(dir, {-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f});
  const auto said = [&](const std::optional<Placement>& placement) {
    installation.scene.placement = placement;
    auto scene = config::load_scene(installation, {});
    EXPECT_TRUE(scene) << scene.error();
    std::string notes;
    for (const std::string& note : scene.value().notes) notes += note + "\n";
    return notes;
  };
  Placement at_eye;
  at_eye.position = eye;
  EXPECT_NE(said(at_eye).find("is inside the model"), std::string::npos) << said(at_eye);
  Placement beside = at_eye;
  beside.position = eye + glm::dvec3(0.55, 0.0, 0.0);
  EXPECT_NE(said(beside).find("is beside the model"), std::string::npos) << said(beside);
  Placement away = at_eye;
  away.position = eye + glm::dvec3(0.0, 0.0, -2.0);
  EXPECT_EQ(said(away).find("the viewer's eye"), std::string::npos) << said(away);
}

// The whole scene moves as one: static instances, animated objects (their
// poses, so their velocity moves too) and lights, which keep lighting it as
// they did (their intensity grows with the square of the scale).
TEST(Placement, PlacingMovesInstancesAnimatedObjectsAndLightsAlike) {
  SceneDefinition scene;
  scene.meshes.push_back({"m", {{glm::vec3(0.0f)}, {glm::vec3(1.0f, 0.0f, 0.0f)}}, {}});
  scene.instances.push_back({0, 0, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(1.0, 0.0, 0.0))});
  scene.instances.push_back({0, 0, 7u, glm::dmat4(1.0)});
  scene.objects.push_back({7, "spinner", [](double seconds) {
                             Pose p;
                             p.position = {0.0, seconds, 0.0};
                             p.rotation = glm::angleAxis(seconds, glm::dvec3(0.0, 0.0, 1.0));
                             p.scale = {1.0, 2.0, 3.0};
                             return p;
                           }});
  scene.lights.push_back({{0.0, 0.0, 1.0}, glm::vec3(1.0f), 2.0f});
  const SceneDefinition before = scene;
  Pose pose;
  pose.position = {1.0, 2.0, 3.0};
  pose.rotation = glm::angleAxis(std::numbers::pi / 2, glm::dvec3(0.0, 1.0, 0.0));
  pose.scale = glm::dvec3(2.0);
  move(scene, pose);
  const glm::dmat4 m = model_matrix(pose);
  const auto expect_matrix = [](const glm::dmat4& a, const glm::dmat4& b, const std::string& what) {
    for (int c = 0; c < 4; ++c) {
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(a[c][r], b[c][r], 1e-12) << what << " [" << c << "][" << r << "]";
    }
  };
  expect_matrix(scene.instances[0].transform, m * before.instances[0].transform, "static instance");
  expect_matrix(scene.instances[1].transform, before.instances[1].transform, "an animated one rides its object");
  for (const double t : {0.0, 0.4, 1.3}) {
    expect_matrix(model_matrix(scene.objects[0].pose_at(t)), m * model_matrix(before.objects[0].pose_at(t)),
                  "object at " + std::to_string(t) + " s");
  }
  const glm::dvec3 light = scene.lights[0].position;
  EXPECT_NEAR(glm::length(light - glm::dvec3(m * glm::dvec4(0.0, 0.0, 1.0, 1.0))), 0.0, 1e-12);
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 8.0f);
  // A fit with nothing to fit leaves the scene where it is, turned.
  SceneDefinition empty;
  Placement fit;
  fit.rotation = pose.rotation;
  fit.fit = Placement::Fit{glm::dvec3(5.0), glm::dvec3(1.0)};
  Pose turned;
  turned.rotation = pose.rotation;
  EXPECT_EQ(place(empty, fit), turned);
}

}  // namespace
}  // namespace optique::scene
