// Rays against a scene as the renderer draws it (common/scene/raycast.h): known
// distances and normals, both faces, the nearest of several surfaces, animated
// instances placed by the state, and no NaN from degenerate geometry.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/builtin.h"
#include "scene/meshes.h"
#include "scene/raycast.h"
#include "util/finite.h"

namespace optique::scene {
namespace {

constexpr double kTolerance = 1e-9;

using util::finite;

void expect_near(const glm::dvec3& actual, const glm::dvec3& expected, double tolerance = kTolerance) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

glm::dmat4 translation(const glm::dvec3& offset) { return glm::translate(glm::dmat4(1.0), offset); }

// A scene of one unit box mesh and one material, with no instances yet.
SceneDefinition box_scene() {
  SceneDefinition scene;
  scene.name = "test";
  scene.meshes.push_back(make_box(glm::vec3(1.0f)));
  scene.materials.push_back({});
  return scene;
}

void add_static(SceneDefinition& scene, std::uint32_t mesh, const glm::dmat4& transform) {
  scene.instances.push_back({mesh, 0, std::nullopt, transform});
}

TEST(CastRay, HitsABoxAtTheExpectedDistanceAndNormal) {
  SceneDefinition scene = box_scene();
  add_static(scene, 0, translation({0.0, 0.0, -5.0}));
  const auto hit = cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 4.5, kTolerance);
  expect_near(hit->point, {0.0, 0.0, -4.5});
  expect_near(hit->normal, {0.0, 0.0, 1.0});
  EXPECT_EQ(hit->instance, 0u);
}

TEST(CastRay, TIsInUnitsOfTheDirection) {
  SceneDefinition scene = box_scene();
  add_static(scene, 0, translation({0.0, 0.0, -5.0}));
  const auto hit = cast_ray(scene, {}, 0.0, {{0.1, 0.2, 0.0}, {0.0, 0.0, -4.0}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 4.5 / 4.0, kTolerance);
  expect_near(hit->point, {0.1, 0.2, -4.5});
  EXPECT_NEAR(glm::length(hit->normal), 1.0, kTolerance);
}

TEST(CastRay, FollowsARotatedScaledInstance) {
  // A 2 × 1 × 1 box turned 90° about y: its long side now runs along z, so a ray
  // along −z meets the face 1 m from its centre.
  SceneDefinition scene = box_scene();
  const glm::dmat4 transform = translation({3.0, 1.0, -6.0}) *
                               glm::mat4_cast(glm::angleAxis(std::numbers::pi / 2.0, glm::dvec3(0.0, 1.0, 0.0))) *
                               glm::scale(glm::dmat4(1.0), glm::dvec3(2.0, 1.0, 1.0));
  add_static(scene, 0, transform);
  const auto along_z = cast_ray(scene, {}, 0.0, {{3.0, 1.0, 0.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(along_z.has_value());
  EXPECT_NEAR(along_z->t, 5.0, kTolerance);
  expect_near(along_z->normal, {0.0, 0.0, 1.0});
  const auto along_x = cast_ray(scene, {}, 0.0, {{0.0, 1.0, -6.0}, {1.0, 0.0, 0.0}});
  ASSERT_TRUE(along_x.has_value());
  EXPECT_NEAR(along_x->t, 2.5, kTolerance);
  expect_near(along_x->normal, {-1.0, 0.0, 0.0});
}

TEST(CastRay, MissesWhatItPassesBy) {
  SceneDefinition scene = box_scene();
  add_static(scene, 0, translation({0.0, 0.0, -5.0}));
  EXPECT_FALSE(cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}}).has_value());         // away from it
  EXPECT_FALSE(cast_ray(scene, {}, 0.0, {{0.6, 0.0, 0.0}, {0.0, 0.0, -1.0}}).has_value());        // beside it
  EXPECT_FALSE(cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}}).has_value());         // across
  EXPECT_FALSE(cast_ray(box_scene(), {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}}).has_value());  // empty
}

TEST(CastRay, FindsTheNearestOfTwoWhateverTheirOrder) {
  for (const bool near_first : {true, false}) {
    SceneDefinition scene = box_scene();
    const glm::dmat4 near = translation({0.0, 0.0, -3.0});
    const glm::dmat4 far = translation({0.0, 0.0, -8.0});
    add_static(scene, 0, near_first ? near : far);
    add_static(scene, 0, near_first ? far : near);
    const auto hit = cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}});
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(hit->t, 2.5, kTolerance);
    EXPECT_EQ(hit->instance, near_first ? 0u : 1u);
  }
}

TEST(CastRay, PlacesAnAnimatedInstanceByTheState) {
  SceneDefinition scene = box_scene();
  scene.objects.push_back({7, "mover", [](double) { return Pose{}; }});
  // The instance's own transform applies before the pose: half the size.
  scene.instances.push_back({0, 0, 7u, glm::scale(glm::dmat4(1.0), glm::dvec3(0.5))});
  SceneState state;
  state.objects[7].now.position = {0.0, 0.0, -5.0};
  state.objects[7].next.position = {2.0, 0.0, -5.0};
  state.objects[7].now.scale = glm::dvec3(2.0);
  state.objects[7].next.scale = glm::dvec3(2.0);

  const Ray at_origin{{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}};
  const Ray at_two{{2.0, 0.0, 0.0}, {0.0, 0.0, -1.0}};
  const Ray at_one{{1.0, 0.0, 0.0}, {0.0, 0.0, -1.0}};
  ASSERT_TRUE(cast_ray(scene, state, 0.0, at_origin).has_value());
  EXPECT_NEAR(cast_ray(scene, state, 0.0, at_origin)->t, 4.5, kTolerance);
  EXPECT_FALSE(cast_ray(scene, state, 0.0, at_two).has_value());
  EXPECT_FALSE(cast_ray(scene, state, 1.0, at_origin).has_value());
  ASSERT_TRUE(cast_ray(scene, state, 1.0, at_two).has_value());
  EXPECT_FALSE(cast_ray(scene, state, 0.0, at_one).has_value());  // its edge reaches x = 1 at fraction 0.25
  ASSERT_TRUE(cast_ray(scene, state, 0.75, at_one).has_value());

  // Not in the state: not drawn, so not met.
  EXPECT_FALSE(cast_ray(scene, SceneState{}, 0.0, at_origin).has_value());
}

TEST(CastRay, FromInsideMeetsTheFarWallFacingTheOrigin) {
  SceneDefinition scene = box_scene();
  add_static(scene, 0, translation({0.0, 0.0, -5.0}));
  const auto hit = cast_ray(scene, {}, 0.0, {{0.0, 0.0, -5.0}, {1.0, 0.0, 0.0}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 0.5, kTolerance);
  expect_near(hit->normal, {-1.0, 0.0, 0.0});  // the box's outward normal is +x: seen from inside
}

TEST(CastRay, SeesBothFacesOfAQuad) {
  SceneDefinition scene = box_scene();
  scene.meshes.push_back(make_quad(2.0f, 2.0f));  // facing +z
  add_static(scene, 1, translation({0.0, 0.0, -1.0}));
  const auto front = cast_ray(scene, {}, 0.0, {{0.3, 0.2, 0.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(front.has_value());
  expect_near(front->normal, {0.0, 0.0, 1.0});
  const auto back = cast_ray(scene, {}, 0.0, {{0.3, 0.2, -2.0}, {0.0, 0.0, 1.0}});
  ASSERT_TRUE(back.has_value());
  EXPECT_NEAR(back->t, 1.0, kTolerance);
  expect_near(back->normal, {0.0, 0.0, -1.0});
  // Through the diagonal the two triangles share: no gap.
  const auto diagonal = cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(diagonal.has_value());
  EXPECT_NEAR(diagonal->t, 1.0, kTolerance);
}

TEST(CastRay, DegenerateTrianglesGiveNoNaN) {
  SceneDefinition scene = box_scene();
  Mesh mesh;
  mesh.name = "degenerate";
  const auto vertex = [](float x, float y, float z) {
    Vertex v;
    v.position = {x, y, z};
    return v;
  };
  mesh.vertices = {vertex(0, 0, -1),   vertex(0, 0, -1),  vertex(1, 0, -1),  // a repeated corner
                   vertex(-1, 0, -1),  vertex(0, 0, -1),  vertex(1, 0, -1),  // collinear
                   vertex(0, 0, -1),   vertex(0, 0, -1),  vertex(0, 0, -1),  // a point
                   vertex(-1, -1, -2), vertex(1, -1, -2), vertex(0, 1, -2)};
  mesh.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  scene.meshes.push_back(mesh);
  add_static(scene, 1, glm::dmat4(1.0));
  // Straight through the degenerate ones: nothing there to meet.
  for (const glm::dvec3& direction : {glm::dvec3(0, 0, -1), glm::dvec3(0.5, 0, -1), glm::dvec3(1, 0, 0)}) {
    const auto hit = cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, direction});
    EXPECT_FALSE(hit.has_value());
  }
  // With a real triangle behind them, that one is met, and only finite numbers come out.
  scene.meshes[1].indices.insert(scene.meshes[1].indices.end(), {9, 10, 11});
  const auto hit = cast_ray(scene, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 2.0, kTolerance);
  EXPECT_TRUE(finite(hit->point));
  EXPECT_TRUE(finite(hit->normal));
  // A ray in the real triangle's plane neither meets it nor makes a NaN.
  EXPECT_FALSE(cast_ray(scene, {}, 0.0, {{-3.0, 0.0, -2.0}, {1.0, 0.0, 0.0}}).has_value());
  // A zero scale flattens every triangle of the box to nothing.
  SceneDefinition flat = box_scene();
  add_static(flat, 0, glm::scale(translation({0.0, 0.0, -5.0}), glm::dvec3(0.0)));
  EXPECT_FALSE(cast_ray(flat, {}, 0.0, {{0.0, 0.0, 0.0}, {0.0, 0.0, -1.0}}).has_value());
}

TEST(CastRay, LargeMeshesAgreeWithTheSurface) {
  // A sphere of thousands of triangles (many chunks): every hit lies on the
  // tessellated sphere, nearer than the true one by at most its sagitta.
  SceneDefinition scene = box_scene();
  scene.meshes.push_back(make_uv_sphere(1.0f, 96, 48));
  ASSERT_GT(scene.meshes[1].indices.size() / 3, 5000u);
  const glm::dvec3 centre(0.0, 0.0, -4.0);
  add_static(scene, 1, translation(centre));
  const RayCaster caster(scene, {}, 0.0);
  const double sagitta = 1.0 - std::cos(std::numbers::pi / 48.0);
  int hits = 0;
  int misses = 0;
  for (int j = -10; j <= 10; ++j) {
    for (int i = -10; i <= 10; ++i) {
      const Ray ray{{0.0, 0.0, 0.0}, {0.026 * i, 0.026 * j, -1.0}};
      const auto hit = caster.cast(ray);
      const auto direct = cast_ray(scene, {}, 0.0, ray);
      ASSERT_EQ(hit.has_value(), direct.has_value());
      if (!hit) {
        ++misses;
        continue;
      }
      ++hits;
      EXPECT_EQ(hit->t, direct->t);
      const double radius = glm::length(hit->point - centre);
      EXPECT_LE(radius, 1.0 + 1e-6);
      EXPECT_GE(radius, 1.0 - 2.0 * sagitta);
      EXPECT_GT(glm::dot(hit->normal, -ray.direction), 0.0);
    }
  }
  EXPECT_GT(hits, 200);
  EXPECT_GT(misses, 0);  // past its rim
}

TEST(CastRay, MeetsABuiltinSceneWhereItsObjectStands) {
  auto scene = builtin_scene("depth-stack");
  ASSERT_TRUE(scene.ok()) << scene.error();
  SceneState state;
  for (const AnimatedObject& object : scene.value().objects) {
    state.objects[object.id] = {object.pose_at(0.0), object.pose_at(0.0)};
  }
  // The nearest slab: centre (−1, 1.2, 0.5), 0.3 × 0.3 × 0.03.
  const auto hit = cast_ray(scene.value(), state, 0.0, {{-1.0, 1.2, 2.0}, {0.0, 0.0, -1.0}});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->t, 1.5 - 0.015, 1e-6);
  EXPECT_EQ(hit->instance, 0u);
}

}  // namespace
}  // namespace optique::scene
