// Procedural meshes (common/scene/meshes.h): well-formed index buffers, unit
// outward normals that agree with the winding, closed surfaces where the shape is
// closed, and the requested sizes.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <ostream>
#include <string>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "scene/meshes.h"

namespace optique::scene {
namespace {

constexpr double kPi = std::numbers::pi;

glm::vec3 corner(const Mesh& mesh, std::size_t triangle, std::size_t k) {
  return mesh.vertices[mesh.indices[3 * triangle + k]].position;
}

// The winding's normal, not normalised (twice the area).
glm::vec3 winding_normal(const Mesh& mesh, std::size_t triangle) {
  const glm::vec3 a = corner(mesh, triangle, 0);
  return glm::cross(corner(mesh, triangle, 1) - a, corner(mesh, triangle, 2) - a);
}

std::size_t triangles(const Mesh& mesh) { return mesh.indices.size() / 3; }

// The volume enclosed, by the divergence theorem: positive when the triangles wind
// counter-clockwise seen from outside.
double signed_volume(const Mesh& mesh) {
  double volume = 0.0;
  for (std::size_t t = 0; t < triangles(mesh); ++t) {
    const glm::dvec3 a(corner(mesh, t, 0)), b(corner(mesh, t, 1)), c(corner(mesh, t, 2));
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return volume;
}

struct Bounds {
  glm::vec3 low{std::numeric_limits<float>::max()};
  glm::vec3 high{std::numeric_limits<float>::lowest()};
};

Bounds bounds(const Mesh& mesh) {
  Bounds b;
  for (const Vertex& v : mesh.vertices) {
    b.low = glm::min(b.low, v.position);
    b.high = glm::max(b.high, v.position);
  }
  return b;
}

void expect_bounds(const Mesh& mesh, const glm::vec3& half, float tolerance = 1e-5f) {
  const Bounds b = bounds(mesh);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(b.low[axis], -half[axis], tolerance) << mesh.name << " axis " << axis;
    EXPECT_NEAR(b.high[axis], half[axis], tolerance) << mesh.name << " axis " << axis;
  }
}

// Positions on a 1e-5 grid, so that vertices duplicated for flat normals or at a
// seam count as one point.
using Key = std::tuple<std::int64_t, std::int64_t, std::int64_t>;
Key key(const glm::vec3& p) {
  return {std::llround(double(p.x) * 1e5), std::llround(double(p.y) * 1e5), std::llround(double(p.z) * 1e5)};
}

// Every edge, by position, is used by exactly two triangles, once in each direction:
// the surface is closed and consistently wound.
void expect_watertight(const Mesh& mesh) {
  std::map<std::pair<Key, Key>, int> directed;
  for (std::size_t t = 0; t < triangles(mesh); ++t) {
    for (std::size_t k = 0; k < 3; ++k) ++directed[{key(corner(mesh, t, k)), key(corner(mesh, t, (k + 1) % 3))}];
  }
  int bad = 0;
  for (const auto& [edge, count] : directed) {
    const auto reverse = directed.find({edge.second, edge.first});
    const int back = reverse == directed.end() ? 0 : reverse->second;
    if (count != 1 || back != 1) ++bad;
  }
  EXPECT_EQ(bad, 0) << mesh.name << ": edges not shared by exactly one opposite-wound triangle";
}

struct MeshCase {
  std::string name;
  std::function<Mesh()> make;
  bool closed = false;  // a single closed surface: watertight, positive volume
};

void PrintTo(const MeshCase& c, std::ostream* out) { *out << c.name; }

std::vector<MeshCase> mesh_cases() {
  return {
      {"box", [] { return make_box({1.0f, 0.5f, 2.0f}); }, true},
      {"cube", [] { return make_box(glm::vec3(1.0f)); }, true},
      {"quad", [] { return make_quad(2.0f, 1.0f); }, false},
      {"sphere", [] { return make_uv_sphere(0.7f, 32, 16); }, true},
      {"coarse_sphere", [] { return make_uv_sphere(1.0f, 3, 2); }, true},
      {"clamped_sphere", [] { return make_uv_sphere(1.0f, 0, 1); }, true},
      {"pyramid", [] { return make_pyramid(1.0f, 1.5f); }, true},
      {"flat_pyramid", [] { return make_pyramid(2.0f, 0.3f); }, true},
      {"torus", [] { return make_torus(0.5f, 0.1f, 48, 16); }, true},
      {"coarse_torus", [] { return make_torus(1.0f, 0.4f, 3, 3); }, true},
      {"wheel", [] { return make_wheel(0.45f, 0.06f, 8); }, false},
      {"wheel_odd_spokes", [] { return make_wheel(1.0f, 0.2f, 5); }, false},
      {"wheel_no_spokes", [] { return make_wheel(1.0f, 0.2f, 0); }, false},
  };
}

class EveryMesh : public ::testing::TestWithParam<MeshCase> {};

TEST_P(EveryMesh, IndicesAreWholeTrianglesInRange) {
  const Mesh mesh = GetParam().make();
  EXPECT_FALSE(mesh.name.empty());
  ASSERT_FALSE(mesh.indices.empty());
  EXPECT_EQ(mesh.indices.size() % 3, 0u);
  for (std::uint32_t i : mesh.indices) ASSERT_LT(i, mesh.vertices.size());
}

TEST_P(EveryMesh, PositionsFiniteNormalsUnit) {
  const Mesh mesh = GetParam().make();
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vertex& v = mesh.vertices[i];
    for (int axis = 0; axis < 3; ++axis) ASSERT_TRUE(std::isfinite(v.position[axis])) << "vertex " << i;
    EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-4f) << "vertex " << i;
  }
}

TEST_P(EveryMesh, NoDegenerateTriangles) {
  const Mesh mesh = GetParam().make();
  for (std::size_t t = 0; t < triangles(mesh); ++t) EXPECT_GT(glm::length(winding_normal(mesh, t)), 1e-8f) << t;
}

// The winding and the vertex normals agree: each triangle faces the way its
// corners' normals point.
TEST_P(EveryMesh, WindingAgreesWithVertexNormals) {
  const Mesh mesh = GetParam().make();
  int disagree = 0;
  for (std::size_t t = 0; t < triangles(mesh); ++t) {
    const glm::vec3 n = glm::normalize(winding_normal(mesh, t));
    for (std::size_t k = 0; k < 3; ++k) {
      if (glm::dot(n, mesh.vertices[mesh.indices[3 * t + k]].normal) <= 0.0f) ++disagree;
    }
  }
  EXPECT_EQ(disagree, 0);
}

INSTANTIATE_TEST_SUITE_P(All, EveryMesh, ::testing::ValuesIn(mesh_cases()),
                         [](const ::testing::TestParamInfo<MeshCase>& param_info) { return param_info.param.name; });

std::vector<MeshCase> closed_cases() {
  std::vector<MeshCase> closed = mesh_cases();
  std::erase_if(closed, [](const MeshCase& c) { return !c.closed; });
  return closed;
}

class ClosedMesh : public ::testing::TestWithParam<MeshCase> {};

TEST_P(ClosedMesh, IsWatertightWithPositiveVolume) {
  const Mesh mesh = GetParam().make();
  expect_watertight(mesh);
  EXPECT_GT(signed_volume(mesh), 0.0);
}

INSTANTIATE_TEST_SUITE_P(All, ClosedMesh, ::testing::ValuesIn(closed_cases()),
                         [](const ::testing::TestParamInfo<MeshCase>& param_info) { return param_info.param.name; });

// Convex shapes: every face points away from the centre.
void expect_faces_point_away_from_origin(const Mesh& mesh) {
  for (std::size_t t = 0; t < triangles(mesh); ++t) {
    const glm::vec3 centroid = (corner(mesh, t, 0) + corner(mesh, t, 1) + corner(mesh, t, 2)) / 3.0f;
    EXPECT_GT(glm::dot(winding_normal(mesh, t), centroid), 0.0f) << mesh.name << " triangle " << t;
  }
}

TEST(Box, ExtentsVolumeAndFlatNormals) {
  const Mesh mesh = make_box({1.0f, 0.5f, 2.0f});
  EXPECT_EQ(triangles(mesh), 12u);
  expect_bounds(mesh, {0.5f, 0.25f, 1.0f}, 0.0f);
  EXPECT_NEAR(signed_volume(mesh), 1.0, 1e-6);
  expect_faces_point_away_from_origin(mesh);
  for (const Vertex& v : mesh.vertices) {
    // Axis-aligned: one component ±1, the others 0.
    EXPECT_FLOAT_EQ(std::abs(v.normal.x) + std::abs(v.normal.y) + std::abs(v.normal.z), 1.0f);
  }
}

TEST(Quad, FacesPlusZWithTheRequestedSize) {
  const Mesh mesh = make_quad(2.0f, 1.0f);
  EXPECT_EQ(triangles(mesh), 2u);
  expect_bounds(mesh, {1.0f, 0.5f, 0.0f}, 0.0f);
  for (std::size_t t = 0; t < triangles(mesh); ++t) EXPECT_GT(winding_normal(mesh, t).z, 0.0f);
}

TEST(UvSphere, EveryVertexOnTheSphereWithRadialNormals) {
  constexpr float kRadius = 0.7f;
  const Mesh mesh = make_uv_sphere(kRadius, 32, 16);
  for (const Vertex& v : mesh.vertices) {
    EXPECT_NEAR(glm::length(v.position), kRadius, 1e-5f);
    EXPECT_NEAR(glm::dot(v.normal, v.position / kRadius), 1.0f, 1e-4f);  // smooth: the radial direction
  }
  // An even number of rings puts a row on the equator, and columns at ±x and ±z.
  expect_bounds(mesh, glm::vec3(kRadius));
  expect_faces_point_away_from_origin(mesh);
}

TEST(UvSphere, TriangleCountAndPolesClosedWithoutDegenerateTriangles) {
  constexpr std::uint32_t kSegments = 12, kRings = 7;
  const Mesh mesh = make_uv_sphere(1.0f, kSegments, kRings);
  // Two triangles per cell, one per cell in the two rows at the poles.
  EXPECT_EQ(triangles(mesh), 2u * kSegments * (kRings - 1));
  const Bounds b = bounds(mesh);
  EXPECT_FLOAT_EQ(b.high.y, 1.0f);
  EXPECT_FLOAT_EQ(b.low.y, -1.0f);
}

TEST(UvSphere, VolumeApproachesTheSphere) {
  const double exact = 4.0 / 3.0 * kPi;
  const double coarse = signed_volume(make_uv_sphere(1.0f, 16, 8));
  const double fine = signed_volume(make_uv_sphere(1.0f, 64, 32));
  EXPECT_LT(coarse, fine);  // inscribed: grows towards the sphere
  EXPECT_LT(fine, exact);
  EXPECT_NEAR(fine, exact, 0.01 * exact);
}

TEST(Pyramid, ExtentsVolumeAndFlatFaces) {
  constexpr float kBase = 1.0f, kHeight = 1.5f;
  const Mesh mesh = make_pyramid(kBase, kHeight);
  EXPECT_EQ(triangles(mesh), 6u);  // four sides and a two-triangle base
  expect_bounds(mesh, {kBase / 2, kHeight / 2, kBase / 2}, 0.0f);
  EXPECT_NEAR(signed_volume(mesh), kBase * kBase * kHeight / 3.0, 1e-6);
  expect_faces_point_away_from_origin(mesh);
  // Flat: the three corners of each triangle share its winding's normal.
  for (std::size_t t = 0; t < triangles(mesh); ++t) {
    const glm::vec3 n = glm::normalize(winding_normal(mesh, t));
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_NEAR(glm::dot(n, mesh.vertices[mesh.indices[3 * t + k]].normal), 1.0f, 1e-5f);
    }
  }
  // The apex is on the y axis; the base faces straight down.
  int base_vertices = 0;
  for (const Vertex& v : mesh.vertices) {
    if (v.normal.y < -0.999f) {
      ++base_vertices;
      EXPECT_FLOAT_EQ(v.position.y, -kHeight / 2);
    }
  }
  EXPECT_EQ(base_vertices, 4);
}

TEST(Torus, VerticesOnTheTubeWithNormalsFromItsCentreLine) {
  constexpr float kMajor = 0.5f, kMinor = 0.1f;
  const Mesh mesh = make_torus(kMajor, kMinor, 48, 16);
  EXPECT_EQ(triangles(mesh), 2u * 48u * 16u);
  for (const Vertex& v : mesh.vertices) {
    const glm::vec2 radial(v.position.x, v.position.y);
    const glm::vec3 centre_line = glm::vec3(glm::normalize(radial) * kMajor, 0.0f);
    EXPECT_NEAR(glm::length(v.position - centre_line), kMinor, 1e-5f);
    EXPECT_NEAR(glm::dot(v.normal, (v.position - centre_line) / kMinor), 1.0f, 1e-4f);
  }
  // In the xy plane around z; 48 steps reach ±x and ±y, 16 reach ±z.
  expect_bounds(mesh, {kMajor + kMinor, kMajor + kMinor, kMinor});
}

TEST(Torus, VolumeApproachesTheTorus) {
  constexpr double kMajor = 0.5, kMinor = 0.1;
  const double exact = 2.0 * kPi * kPi * kMajor * kMinor * kMinor;
  const double volume = signed_volume(make_torus(float(kMajor), float(kMinor), 96, 32));
  EXPECT_NEAR(volume, exact, 0.01 * exact);
}

TEST(Wheel, FitsItsRadiusAndRimThickness) {
  constexpr float kRadius = 0.45f, kRim = 0.06f;
  const Mesh mesh = make_wheel(kRadius, kRim, 8);
  expect_bounds(mesh, {kRadius, kRadius, kRim / 2});
  float farthest = 0.0f;
  for (const Vertex& v : mesh.vertices) farthest = std::max(farthest, glm::length(glm::vec2(v.position)));
  EXPECT_NEAR(farthest, kRadius, 1e-5f);
}

TEST(Wheel, EachSpokeAddsABox) {
  const std::size_t none = triangles(make_wheel(1.0f, 0.2f, 0));
  const std::size_t box = triangles(make_box(glm::vec3(1.0f)));
  for (std::uint32_t spokes : {1u, 3u, 8u, 12u}) {
    EXPECT_EQ(triangles(make_wheel(1.0f, 0.2f, spokes)), none + spokes * box) << spokes;
  }
}

// The spokes are evenly spread around the axle: the surface's centroid (by area)
// is on it, whatever their number; with one spoke it is not.
TEST(Wheel, SpokesEvenlySpreadAroundTheAxle) {
  const auto surface_centroid = [](const Mesh& mesh) {
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (std::size_t t = 0; t < triangles(mesh); ++t) {
      const double a = 0.5 * glm::length(glm::dvec3(winding_normal(mesh, t)));
      sum += a * glm::dvec3(corner(mesh, t, 0) + corner(mesh, t, 1) + corner(mesh, t, 2)) / 3.0;
      area += a;
    }
    return sum / area;
  };
  for (std::uint32_t spokes : {2u, 3u, 5u, 8u}) {
    EXPECT_NEAR(glm::length(surface_centroid(make_wheel(1.0f, 0.2f, spokes))), 0.0, 1e-5) << spokes;
  }
  EXPECT_GT(surface_centroid(make_wheel(1.0f, 0.2f, 1)).x, 0.01);  // the one spoke is along +x
}

TEST(Wheel, RimThicknessIsClampedToTheRadius) {
  const Mesh mesh = make_wheel(0.5f, 3.0f, 4);
  expect_bounds(mesh, {0.5f, 0.5f, 0.25f});
}

}  // namespace
}  // namespace optique::scene
