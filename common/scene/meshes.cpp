#include "scene/meshes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace optique::scene {
namespace {

// Appends a flat quad a-b-c-d (counter-clockwise seen from outside).
void add_face(Mesh& mesh, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
              const glm::vec3& normal) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto& p : {a, b, c, d}) mesh.vertices.push_back({p, normal, glm::vec2(0.0f)});
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
}

// Appends a flat triangle a-b-c (counter-clockwise seen from outside); its normal
// follows from the winding.
void add_triangle(Mesh& mesh, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const glm::vec3 normal = glm::normalize(glm::cross(b - a, c - a));
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto& p : {a, b, c}) mesh.vertices.push_back({p, normal, glm::vec2(0.0f)});
  for (std::uint32_t i : {0u, 1u, 2u}) mesh.indices.push_back(base + i);
}

// Appends the two triangles of grid cell (a, b, c, d), counter-clockwise seen from
// outside, leaving out either one where it would be degenerate.
void add_cell(Mesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, bool first = true,
              bool second = true) {
  if (first) mesh.indices.insert(mesh.indices.end(), {a, b, c});
  if (second) mesh.indices.insert(mesh.indices.end(), {a, c, d});
}

// Appends `part`, rotated by `rotation` (orthonormal) and then moved by `offset`.
void append(Mesh& mesh, const Mesh& part, const glm::mat3& rotation = glm::mat3(1.0f),
            const glm::vec3& offset = glm::vec3(0.0f)) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const Vertex& v : part.vertices) {
    mesh.vertices.push_back({rotation * v.position + offset, glm::normalize(rotation * v.normal), v.uv});
  }
  for (std::uint32_t i : part.indices) mesh.indices.push_back(base + i);
}

// A rotation about +z by `radians` (counter-clockwise seen from +z).
glm::mat3 about_z(double radians) {
  const auto c = static_cast<float>(std::cos(radians));
  const auto s = static_cast<float>(std::sin(radians));
  // Column-major: the images of x, y and z.
  return glm::mat3(glm::vec3(c, s, 0.0f), glm::vec3(-s, c, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f));
}

}  // namespace

Mesh make_box(const glm::vec3& size) {
  Mesh mesh{"box", {}, {}};
  const glm::vec3 h = size * 0.5f;
  // For each axis and sign: the face's normal and two in-plane axes (u × v = normal).
  const std::array<std::array<glm::vec3, 3>, 6> faces{{
      {glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0)},
      {glm::vec3(-1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, 1, 0)},
      {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, -1)},
      {glm::vec3(0, -1, 0), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1)},
      {glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)},
      {glm::vec3(0, 0, -1), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0)},
  }};
  for (const auto& [n, u, v] : faces) {
    const glm::vec3 c = n * h;
    const glm::vec3 du = u * h;
    const glm::vec3 dv = v * h;
    add_face(mesh, c - du - dv, c + du - dv, c + du + dv, c - du + dv, n);
  }
  return mesh;
}

Mesh make_quad(float width, float height) {
  Mesh mesh{"quad", {}, {}};
  const float x = width * 0.5f;
  const float y = height * 0.5f;
  add_face(mesh, {-x, -y, 0}, {x, -y, 0}, {x, y, 0}, {-x, y, 0}, {0, 0, 1});
  return mesh;
}

Mesh make_uv_sphere(float radius, std::uint32_t segments, std::uint32_t rings) {
  segments = std::max(segments, 3u);
  rings = std::max(rings, 2u);
  Mesh mesh{"uv-sphere", {}, {}};
  // Rows from the north pole (i = 0) to the south pole (i = rings); columns around
  // +y, counter-clockwise seen from above, the last repeating the first exactly so
  // the seam closes. Poles are exact so that the mesh closes there too.
  const std::uint32_t columns = segments + 1;
  mesh.vertices.reserve(static_cast<std::size_t>(rings + 1) * columns);
  for (std::uint32_t i = 0; i <= rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    const double sin_theta = (i == 0 || i == rings) ? 0.0 : std::sin(theta);
    const double cos_theta = i == 0 ? 1.0 : i == rings ? -1.0 : std::cos(theta);
    for (std::uint32_t j = 0; j < columns; ++j) {
      const double phi = kTau * (j % segments) / segments;
      const glm::vec3 normal(static_cast<float>(sin_theta * std::cos(phi)), static_cast<float>(cos_theta),
                             static_cast<float>(-sin_theta * std::sin(phi)));
      mesh.vertices.push_back({normal * radius, glm::normalize(normal), glm::vec2(0.0f)});
    }
  }
  for (std::uint32_t i = 0; i < rings; ++i) {
    for (std::uint32_t j = 0; j < segments; ++j) {
      const std::uint32_t a = i * columns + j;  // top left, seen from outside
      const std::uint32_t b = a + columns;      // below it
      // Next to a pole, one of the cell's triangles has two corners on it: left out.
      add_cell(mesh, a, b, b + 1, a + 1, /*first=*/i + 1 < rings, /*second=*/i > 0);
    }
  }
  return mesh;
}

Mesh make_pyramid(float base, float height) {
  Mesh mesh{"pyramid", {}, {}};
  const float b = base * 0.5f;
  const float h = height * 0.5f;
  // The base's corners counter-clockwise seen from above: each side runs from one
  // corner to the next and up to the apex.
  const std::array<glm::vec3, 4> corners{{{-b, -h, b}, {b, -h, b}, {b, -h, -b}, {-b, -h, -b}}};
  const glm::vec3 apex(0.0f, h, 0.0f);
  for (std::size_t i = 0; i < corners.size(); ++i) add_triangle(mesh, corners[i], corners[(i + 1) % 4], apex);
  // The base, counter-clockwise seen from below.
  add_face(mesh, corners[3], corners[2], corners[1], corners[0], {0.0f, -1.0f, 0.0f});
  return mesh;
}

Mesh make_torus(float major_radius, float minor_radius, std::uint32_t segments, std::uint32_t sides) {
  segments = std::max(segments, 3u);
  sides = std::max(sides, 3u);
  Mesh mesh{"torus", {}, {}};
  // Rows i around the ring (counter-clockwise seen from +z), columns j around the
  // tube (from the outside towards +z); the last row and column repeat the first
  // exactly so the mesh closes.
  const std::uint32_t columns = sides + 1;
  mesh.vertices.reserve(static_cast<std::size_t>(segments + 1) * columns);
  for (std::uint32_t i = 0; i <= segments; ++i) {
    const double u = kTau * (i % segments) / segments;
    const glm::dvec3 outward(std::cos(u), std::sin(u), 0.0);
    for (std::uint32_t j = 0; j < columns; ++j) {
      const double v = kTau * (j % sides) / sides;
      const glm::dvec3 normal = std::cos(v) * outward + std::sin(v) * glm::dvec3(0.0, 0.0, 1.0);
      const glm::dvec3 position = double(major_radius) * outward + double(minor_radius) * normal;
      mesh.vertices.push_back({glm::vec3(position), glm::vec3(glm::normalize(normal)), glm::vec2(0.0f)});
    }
  }
  for (std::uint32_t i = 0; i < segments; ++i) {
    for (std::uint32_t j = 0; j < sides; ++j) {
      const std::uint32_t a = i * columns + j;
      const std::uint32_t b = a + columns;  // one step around the ring
      add_cell(mesh, a, b, b + 1, a + 1);
    }
  }
  return mesh;
}

Mesh make_wheel(float radius, float rim_thickness, std::uint32_t spokes) {
  rim_thickness = std::clamp(rim_thickness, radius * 1e-3f, radius);
  const float tube = rim_thickness * 0.5f;
  const float centre_line = radius - tube;  // the rim's tube centre
  Mesh mesh{"wheel", {}, {}};
  append(mesh, make_torus(centre_line, tube, 48, 12));
  // The hub: a block on the axle, as deep as the rim, well inside it.
  const float hub = std::min(rim_thickness * 1.5f, centre_line);
  append(mesh, make_box({hub, hub, rim_thickness}));
  // Spokes from the axle out to the rim's centre line, thinner than the rim.
  const float width = rim_thickness * 0.4f;
  const Mesh spoke = make_box({centre_line, width, width});
  for (std::uint32_t k = 0; k < spokes; ++k) {
    const glm::mat3 rotation = about_z(kTau * k / spokes);
    append(mesh, spoke, rotation, rotation * glm::vec3(centre_line * 0.5f, 0.0f, 0.0f));
  }
  return mesh;
}

}  // namespace optique::scene
