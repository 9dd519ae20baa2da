#pragma once
// Procedural meshes for the built-in scenes, centred on the origin, with outward
// normals (flat where the surface has edges, smooth where it is round).
// Triangles are counter-clockwise seen from outside; every normal is unit length.

#include <cstdint>
#include <numbers>

#include "scene/definition.h"

namespace optique::scene {

inline constexpr double kTau = 2.0 * std::numbers::pi;  // a whole turn, radians

[[nodiscard]] Mesh make_box(const glm::vec3& size);       // axis-aligned, centred
[[nodiscard]] Mesh make_quad(float width, float height);  // in the xy plane, facing +z

// A sphere of `radius` in `segments` slices around the y axis (at least 3) and
// `rings` stacks from pole to pole (at least 2), with smooth normals. The poles
// are at ±y; the rows next to them close in single triangles, so no triangle is
// degenerate.
[[nodiscard]] Mesh make_uv_sphere(float radius, std::uint32_t segments, std::uint32_t rings);

// A square-based pyramid: the base, `base` wide in x and z, at y = −height/2, the
// apex at y = +height/2 (so its bounding box is centred). Flat normals per face.
[[nodiscard]] Mesh make_pyramid(float base, float height);

// A ring in the xy plane around the z axis: its tube's centre line is a circle of
// `major_radius`, the tube `minor_radius` thick, in `segments` steps around the
// ring (at least 3) and `sides` around the tube (at least 3). Smooth normals.
[[nodiscard]] Mesh make_torus(float major_radius, float minor_radius, std::uint32_t segments, std::uint32_t sides);

// A wheel in the xy plane, axle along z, `radius` to the outside of the rim: a
// torus rim `rim_thickness` thick, a box hub, and `spokes` box spokes from the hub
// to the rim, merged into one mesh (its parts overlap; each part is closed). Its
// extent in z is ±rim_thickness/2. `rim_thickness` is clamped to (0, radius].
[[nodiscard]] Mesh make_wheel(float radius, float rim_thickness, std::uint32_t spokes);

}  // namespace optique::scene
