#include "scene/meshes.h"

#include <array>

namespace optique::scene {
namespace {

// Appends a flat quad a-b-c-d (counter-clockwise seen from outside).
void add_face(Mesh& mesh, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
              const glm::vec3& normal) {
  const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto& p : {a, b, c, d}) mesh.vertices.push_back({p, normal});
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
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

}  // namespace optique::scene
