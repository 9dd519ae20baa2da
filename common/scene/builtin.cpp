#include "scene/builtin.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "scene/meshes.h"

namespace optique::scene {
namespace {

// World frame: metres, y up, the viewer near z = +2 looking down −z; objects sit
// around (0, 1.2, −0.5), behind a front wall at z = 0.
const glm::dvec3 kStage{0.0, 1.2, -0.5};
// Spelled out: a braced {} quaternion is all zeros, not the identity.
const glm::dquat kUpright{1.0, 0.0, 0.0, 0.0};

glm::dquat spin(const glm::dvec3& axis, double radians) { return glm::angleAxis(radians, glm::normalize(axis)); }

// Adds a mesh and a material and returns their indices.
std::uint32_t add_mesh(SceneDefinition& scene, Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  return static_cast<std::uint32_t>(scene.meshes.size() - 1);
}

std::uint32_t add_material(SceneDefinition& scene, const Material& material) {
  scene.materials.push_back(material);
  return static_cast<std::uint32_t>(scene.materials.size() - 1);
}

// An instance of `mesh` riding on a new animated object.
void add_animated(SceneDefinition& scene, std::uint32_t mesh, std::uint32_t material, std::string name,
                  std::function<Pose(double)> pose_at) {
  const auto id = static_cast<std::uint32_t>(scene.objects.size() + 1);
  scene.objects.push_back({id, std::move(name), std::move(pose_at)});
  scene.instances.push_back({mesh, material, id, glm::dmat4(1.0)});
}

// A still instance's transform: scaled by `size`, rolled about z, then moved to `position`.
glm::dmat4 placed(const glm::dvec3& position, const glm::dvec3& size, double roll = 0.0) {
  return glm::translate(glm::dmat4(1.0), position) * glm::rotate(glm::dmat4(1.0), roll, glm::dvec3(0, 0, 1)) *
         glm::scale(glm::dmat4(1.0), size);
}

SceneDefinition cubes() {
  // Five unit cubes (scaled to 25 cm) on a ring, each turning about its own axis at
  // its own rate, under three white-ish point lights.
  SceneDefinition scene;
  scene.name = "cubes";
  const auto cube = add_mesh(scene, make_box(glm::vec3(1.0f)));
  constexpr int kCount = 5;
  for (int i = 0; i < kCount; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / kCount;
    const glm::dvec3 where = kStage + glm::dvec3(0.7 * std::cos(angle), 0.35 * std::sin(angle), 0.0);
    const glm::dvec3 axis(std::cos(angle + 1.0), 1.0, std::sin(angle));
    const double rate = 0.6 + 0.3 * i;  // rad/s
    const float hue = static_cast<float>(i) / kCount;
    const auto material = add_material(
        scene, {glm::vec3(0.25f + 0.6f * hue, 0.7f - 0.5f * hue, 0.3f + 0.4f * std::abs(0.5f - hue)), 0.0f, 0.4f, {}});
    add_animated(scene, cube, material, "cube-" + std::to_string(i + 1), [where, axis, rate](double t) {
      return Pose{where, spin(axis, rate * t), glm::dvec3(0.25)};
    });
  }
  scene.lights = {{{-1.0, 2.2, 1.0}, {1.0f, 0.95f, 0.9f}, 2.0f},
                  {{1.2, 1.6, 0.8}, {0.9f, 0.95f, 1.0f}, 1.5f},
                  {{0.0, 0.4, 1.2}, {1.0f, 1.0f, 1.0f}, 0.8f}};
  return scene;
}

SceneDefinition cubes_backdrop() {
  // The cubes in front of a matte back wall that their lights shade smoothly:
  // light everywhere on the screen, so seams and masks show.
  SceneDefinition scene = cubes();
  scene.name = "cubes-backdrop";
  const auto wall = add_mesh(scene, make_quad(8.0f, 4.0f));
  const auto matte = add_material(scene, {glm::vec3(0.55f, 0.5f, 0.45f), 0.0f, 0.9f, {}});
  scene.instances.push_back({wall, matte, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 1.2, -1.4))});
  return scene;
}

// A slowly turning glossy statue before a matte wall, lit by `count` coloured
// point lights spread in front of the wall: every light shades the whole wall
// smoothly and puts its own highlight on the statue, so a split of the lights
// across projectors shows anywhere it is wrong. The total light stays the same
// whatever the count.
SceneDefinition many_lights(int count) {
  SceneDefinition scene;
  scene.name = count == 20 ? "many-lights" : "many-lights-" + std::to_string(count);
  scene.ambient = glm::vec3(0.01f);
  const auto box = add_mesh(scene, make_box(glm::vec3(1.0f)));
  const auto glossy = add_material(scene, {glm::vec3(0.8f), 0.0f, 0.25f, {}});
  add_animated(scene, box, glossy, "statue", [](double t) {
    return Pose{kStage, spin({0, 1, 0}, 0.3 * t), glm::dvec3(0.6)};
  });
  const auto wall = add_mesh(scene, make_quad(8.0f, 4.0f));
  const auto matte = add_material(scene, {glm::vec3(0.5f), 0.0f, 0.9f, {}});
  scene.instances.push_back({wall, matte, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 1.2, -1.4))});
  const float intensity = 0.25f * 20.0f / static_cast<float>(count);
  for (int i = 0; i < count; ++i) {
    // A golden-angle spiral over an ellipse in front of the stage, at varying
    // distances from the wall: no two lights alike.
    const double f = (i + 0.5) / count;
    const double angle = 2.399963229728653 * i;
    const double r = std::sqrt(f);
    const float h = static_cast<float>(i) / static_cast<float>(count);
    const glm::vec3 colour(0.5f + 0.5f * std::cos(6.2832f * h), 0.5f + 0.5f * std::cos(6.2832f * (h - 0.333f)),
                           0.5f + 0.5f * std::cos(6.2832f * (h - 0.667f)));
    scene.lights.push_back({kStage + glm::dvec3(1.6 * r * std::cos(angle), 0.8 * r * std::sin(angle),
                                                -0.3 + 1.2 * std::fmod(0.618033988749895 * i, 1.0)),
                            colour, intensity});
  }
  return scene;
}

SceneDefinition depth_stack() {
  // Slabs at several depths that do not move: after the snapshot, deltas are empty.
  SceneDefinition scene;
  scene.name = "depth-stack";
  const auto slab = add_mesh(scene, make_box(glm::vec3(1.0f, 1.0f, 0.1f)));
  const std::array<double, 5> depths{0.5, -0.5, -1.5, -3.0, -6.0};
  for (std::size_t i = 0; i < depths.size(); ++i) {
    const glm::dvec3 where(-1.0 + 0.5 * static_cast<double>(i), 1.2, depths[i]);
    const float shade = 0.3f + 0.15f * static_cast<float>(i);
    const auto material = add_material(scene, {glm::vec3(shade, 0.8f - shade * 0.5f, 0.5f), 0.0f, 0.6f, {}});
    add_animated(scene, slab, material, "slab-" + std::to_string(i + 1), [where](double) {
      return Pose{where, kUpright, glm::dvec3(0.3)};
    });
  }
  scene.lights = {{{0.0, 2.5, 2.0}, {1.0f, 1.0f, 1.0f}, 4.0f}};
  scene.ambient = glm::vec3(0.05f);
  return scene;
}

SceneDefinition moving_square() {
  // A white, self-lit square crossing 3 m in 1 s over black, then jumping back:
  // fast enough that colour fields separate visibly.
  SceneDefinition scene;
  scene.name = "moving-square";
  scene.ambient = glm::vec3(0.0f);
  const auto quad = add_mesh(scene, make_quad(1.0f, 1.0f));
  const auto white = add_material(scene, {glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(1.0f)});
  add_animated(scene, quad, white, "square", [](double t) {
    const double phase = t - std::floor(t);
    return Pose{glm::dvec3(-1.5 + 3.0 * phase, 1.2, -0.2), kUpright, glm::dvec3(0.2)};
  });
  return scene;
}

// Back and forth between −amplitude and +amplitude at `speed`, starting at 0
// going up: a triangle wave, so the motion never jumps.
double to_and_fro(double t, double amplitude, double speed) {
  const double period = 4.0 * amplitude / speed;
  const double from_low = t + 0.25 * period;  // −amplitude a quarter period before t = 0
  const double phase = from_low - period * std::floor(from_low / period);
  const double travelled = speed * phase;
  return travelled <= 2.0 * amplitude ? travelled - amplitude : 3.0 * amplitude - travelled;
}

// An sRGB8 texture of `width` × `height` texels, each `texel(x, y)`'s colour.
Texture make_texture(std::string name, int width, int height, const std::function<glm::u8vec3(int, int)>& texel) {
  Texture texture{std::move(name), width, height, {}};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::u8vec3 c = texel(x, y);
      texture.rgba.insert(texture.rgba.end(), {c.r, c.g, c.b, 255});
    }
  }
  return texture;
}

SceneDefinition scrolling_stripes() {
  // A 2 m × 0.5 m panel of black and white stripes of several widths (like the
  // strokes of large text), lit evenly by ambient light alone, sliding left and
  // right at 1.5 m/s: edges across the motion everywhere, the hardest case for
  // colour fields.
  SceneDefinition scene;
  scene.name = "scrolling-stripes";
  scene.ambient = glm::vec3(1.0f);
  // 4 texels per 5 cm; white runs of 2, 4, 6 and 4 texels between black ones of
  // 2, 2, 4 and 8, repeated every 32.
  constexpr std::array<int, 8> kRuns{2, 2, 4, 2, 6, 4, 4, 8};
  scene.textures.push_back(make_texture("stripes", 160, 4, [&](int x, int) {
    int at = x % 32;
    for (std::size_t i = 0; i < kRuns.size(); ++i) {
      if (at < kRuns[i]) return i % 2 == 0 ? glm::u8vec3(255) : glm::u8vec3(0);
      at -= kRuns[i];
    }
    return glm::u8vec3(0);
  }));
  const auto panel = add_mesh(scene, make_quad(2.0f, 0.5f));
  const auto stripes = add_material(scene, {glm::vec3(1.0f), 0.0f, 1.0f, {}, 0u});
  add_animated(scene, panel, stripes, "stripes", [](double t) {
    return Pose{glm::dvec3(to_and_fro(t, 0.8, 1.5), 1.2, -0.2), kUpright, glm::dvec3(1.0)};
  });
  return scene;
}

SceneDefinition pinball() {
  // The fast-motion paper's pinball: a small bright steel ball bouncing across a
  // playfield at about 3 m/s, in front of a checkered board and its bumpers and
  // behind three posts, under eight coloured lights: a small fast object, things
  // it uncovers at other depths, and shading that costs something to draw.
  SceneDefinition scene;
  scene.name = "pinball";
  scene.ambient = glm::vec3(0.15f);
  // 10 cm squares, 8 texels each: sharp enough edges for the eye to lose.
  scene.textures.push_back(make_texture("board", 256, 144, [](int x, int y) {
    return (x / 8 + y / 8) % 2 == 0 ? glm::u8vec3(60, 100, 190) : glm::u8vec3(50, 160, 90);
  }));
  const auto board = add_mesh(scene, make_quad(3.2f, 1.8f));
  const auto checker = add_material(scene, {glm::vec3(1.0f), 0.0f, 0.7f, {}, 0u});
  scene.instances.push_back({board, checker, std::nullopt, placed({0.0, 1.2, -0.6}, glm::dvec3(1.0))});
  const auto bumper = add_mesh(scene, make_uv_sphere(1.0f, 32, 16));
  const auto red = add_material(scene, {glm::vec3(0.8f, 0.1f, 0.1f), 0.0f, 0.3f, {}});
  const auto yellow = add_material(scene, {glm::vec3(0.9f, 0.8f, 0.1f), 0.0f, 0.3f, {}});
  for (int i = 0; i < 6; ++i) {
    const glm::dvec3 where(-1.1 + 0.45 * i, 1.2 + (i % 2 == 0 ? 0.35 : -0.3), -0.45);
    scene.instances.push_back({bumper, i % 2 == 0 ? red : yellow, std::nullopt, placed(where, glm::dvec3(0.1))});
  }
  const auto post = add_mesh(scene, make_box(glm::vec3(1.0f)));
  const auto white = add_material(scene, {glm::vec3(0.85f), 0.0f, 0.5f, {}});
  for (int i = 0; i < 3; ++i) {
    scene.instances.push_back({post, white, std::nullopt, placed({-0.8 + 0.8 * i, 1.2, -0.1}, {0.04, 0.6, 0.04})});
  }
  const auto ball = add_mesh(scene, make_uv_sphere(1.0f, 32, 16));
  const auto steel = add_material(scene, {glm::vec3(0.9f), 1.0f, 0.15f, glm::vec3(0.8f)});
  add_animated(scene, ball, steel, "ball", [](double t) {
    return Pose{glm::dvec3(to_and_fro(t, 1.4, 2.6), 1.2 + to_and_fro(t + 0.3, 0.7, 1.9), -0.3), kUpright,
                glm::dvec3(0.035)};
  });
  for (int i = 0; i < 8; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / 8.0;
    const float h = static_cast<float>(i) / 8.0f;
    const glm::vec3 colour(0.6f + 0.4f * std::cos(6.2832f * h), 0.6f + 0.4f * std::cos(6.2832f * (h - 0.333f)),
                           0.6f + 0.4f * std::cos(6.2832f * (h - 0.667f)));
    scene.lights.push_back({{1.5 * std::cos(angle), 1.2 + 0.8 * std::sin(angle), 0.6}, colour, 3.0f});
  }
  return scene;
}

// The up-conversion set: the test scenes of the motion-compensated frame-rate
// up-conversion paper (docs/design.md). One
// object each (the falling ring has a static plinth too), turning or moving at a
// known rate, under one or two point lights.

constexpr double kFastTurnsPerSecond = 2.0;
constexpr double kSlowTurnsPerSecond = 0.25;
// "Zoom in/out": z swings kZoomSwing either side of kZoomCentre (−1.2 to −0.2),
// once per kZoomPeriod, starting far away: in front of the 3 m CAVE's back wall
// (z = −1.5) and of its viewer (z = 0).
constexpr double kZoomCentre = -0.7;
constexpr double kZoomSwing = 0.5;
constexpr double kZoomPeriod = 4.0;  // s

// Two white lights, a key light up and to the left and a dimmer fill to the right,
// both in front of the stage.
void add_key_and_fill(SceneDefinition& scene) {
  scene.lights = {{{-0.9, 2.3, 1.0}, {1.0f, 0.96f, 0.9f}, 2.5f}, {{1.1, 1.4, 0.7}, {0.85f, 0.9f, 1.0f}, 1.0f}};
}

// A tilt that shows three sides of an object turning about the vertical.
glm::dquat three_quarter_tilt() { return spin({1.0, 0.0, 0.2}, 0.45); }

// About the vertical through the stage, after a fixed tilt, at `turns_per_second`.
std::function<Pose(double)> turning_about_vertical(double turns_per_second, glm::dquat tilt, double size) {
  return [turns_per_second, tilt, size](double t) {
    return Pose{kStage, glm::normalize(spin({0.0, 1.0, 0.0}, kTau * turns_per_second * t) * tilt), glm::dvec3(size)};
  };
}

// Where a zooming object is at `t`: far at t = 0, nearest at half a period.
glm::dvec3 zoom_position(double t) {
  return {kStage.x, kStage.y, kZoomCentre - kZoomSwing * std::cos(kTau * t / kZoomPeriod)};
}

SceneDefinition rotating_cube(std::string name, double turns_per_second) {
  SceneDefinition scene;
  scene.name = std::move(name);
  const auto cube = add_mesh(scene, make_box(glm::vec3(1.0f)));
  const auto orange = add_material(scene, {glm::vec3(0.85f, 0.45f, 0.15f), 0.0f, 0.45f, {}});
  add_animated(scene, cube, orange, "cube", turning_about_vertical(turns_per_second, three_quarter_tilt(), 0.4));
  add_key_and_fill(scene);
  return scene;
}

SceneDefinition cube_fast_rotation() { return rotating_cube("cube-fast-rotation", kFastTurnsPerSecond); }
SceneDefinition cube_slow_rotation() { return rotating_cube("cube-slow-rotation", kSlowTurnsPerSecond); }

SceneDefinition cube_zoom() {
  // A cube, tilted to show three faces, moving towards the viewer and away again.
  SceneDefinition scene;
  scene.name = "cube-zoom";
  const auto cube = add_mesh(scene, make_box(glm::vec3(1.0f)));
  const auto teal = add_material(scene, {glm::vec3(0.15f, 0.6f, 0.65f), 0.0f, 0.4f, {}});
  const glm::dquat tilt = glm::normalize(spin({0.0, 1.0, 0.0}, 0.6) * three_quarter_tilt());
  add_animated(scene, cube, teal, "cube", [tilt](double t) { return Pose{zoom_position(t), tilt, glm::dvec3(0.35)}; });
  add_key_and_fill(scene);
  return scene;
}

SceneDefinition rotating_pyramid(std::string name, double turns_per_second) {
  SceneDefinition scene;
  scene.name = std::move(name);
  const auto pyramid = add_mesh(scene, make_pyramid(1.0f, 1.0f));
  const auto yellow = add_material(scene, {glm::vec3(0.9f, 0.75f, 0.2f), 0.0f, 0.5f, {}});
  // Tipped a little towards the viewer so the apex and the base's edges both show.
  add_animated(scene, pyramid, yellow, "pyramid",
               turning_about_vertical(turns_per_second, spin({1.0, 0.0, 0.0}, 0.25), 0.5));
  add_key_and_fill(scene);
  return scene;
}

SceneDefinition pyramid_fast_rotation() { return rotating_pyramid("pyramid-fast-rotation", kFastTurnsPerSecond); }
SceneDefinition pyramid_slow_rotation() { return rotating_pyramid("pyramid-slow-rotation", kSlowTurnsPerSecond); }

// An eight-spoked wheel, 0.9 m across, facing the viewer (axle along z) and turned
// a little about the vertical so the rim shows depth; it turns once a second.
constexpr double kWheelTurnsPerSecond = 1.0;
const glm::dquat kWheelYaw{spin({0.0, 1.0, 0.0}, 0.3)};

glm::dquat wheel_rotation_at(double t) {
  return glm::normalize(kWheelYaw * spin({0.0, 0.0, 1.0}, -kTau * kWheelTurnsPerSecond * t));  // clockwise as seen
}

SceneDefinition wheel_scene(std::string name, std::function<Pose(double)> pose_at) {
  SceneDefinition scene;
  scene.name = std::move(name);
  const auto wheel = add_mesh(scene, make_wheel(0.45f, 0.06f, 8));
  const auto steel = add_material(scene, {glm::vec3(0.75f, 0.75f, 0.8f), 0.6f, 0.35f, {}});
  add_animated(scene, wheel, steel, "wheel", std::move(pose_at));
  add_key_and_fill(scene);
  return scene;
}

SceneDefinition wheel_rotation() {
  return wheel_scene("wheel-rotation", [](double t) { return Pose{kStage, wheel_rotation_at(t), glm::dvec3(1.0)}; });
}

SceneDefinition wheel_in_out() {
  return wheel_scene("wheel-in-out", [](double t) {
    return Pose{zoom_position(t), wheel_rotation_at(t), glm::dvec3(1.0)};
  });
}

SceneDefinition falling_ring() {
  // A ring dropped onto a plinth, bouncing without loss (so its motion repeats with
  // a fixed period), tilted so its hole shows and turning slowly about the vertical.
  SceneDefinition scene;
  scene.name = "falling-ring";
  constexpr double kGravity = 9.81;               // m/s²
  constexpr double kMajor = 0.25, kMinor = 0.06;  // m
  constexpr double kTilt = 0.35;                  // rad from lying flat
  constexpr double kPlinthTop = 0.55;             // m above the floor
  const double top = kStage.y + 0.6;              // the ring's centre at the top
  // The ring's centre when its lowest point touches the plinth.
  const double contact = kPlinthTop + kMajor * std::sin(kTilt) + kMinor;
  const double drop = top - contact;
  const double period = 2.0 * std::sqrt(2.0 * drop / kGravity);  // top → plinth → top

  const auto plinth = add_mesh(scene, make_box(glm::vec3(1.0f, 0.1f, 0.8f)));
  const auto grey = add_material(scene, {glm::vec3(0.5f, 0.5f, 0.52f), 0.0f, 0.8f, {}});
  scene.instances.push_back(
      {plinth, grey, std::nullopt, glm::translate(glm::dmat4(1.0), glm::dvec3(kStage.x, kPlinthTop - 0.05, kStage.z))});

  const auto ring = add_mesh(scene, make_torus(static_cast<float>(kMajor), static_cast<float>(kMinor), 48, 16));
  const auto red = add_material(scene, {glm::vec3(0.8f, 0.15f, 0.12f), 0.0f, 0.35f, {}});
  // The torus lies in the xy plane: a quarter turn about x lays it flat, less the tilt.
  const glm::dquat lay = spin({1.0, 0.0, 0.0}, std::numbers::pi / 2.0 - kTilt);
  add_animated(scene, ring, red, "ring", [period, top, lay](double t) {
    const double phase = t - period * std::floor(t / period);           // in [0, period)
    const double fall = period / 2.0 - std::abs(phase - period / 2.0);  // time from the nearest top
    const double y = top - 0.5 * kGravity * fall * fall;
    return Pose{{kStage.x, y, kStage.z}, glm::normalize(spin({0.0, 1.0, 0.0}, 0.8 * t) * lay), glm::dvec3(1.0)};
  });
  add_key_and_fill(scene);
  return scene;
}

// Probes for tests: self-lit shapes on black at known places, so an image
// measurement has nothing else to separate them from.
SceneDefinition probe(std::string name) {
  SceneDefinition scene;
  scene.name = std::move(name);
  scene.ambient = glm::vec3(0.0f);
  scene.materials.push_back({glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(1.0f)});
  return scene;
}

SceneDefinition stereo_probe() {
  // A 10 cm square 1 m behind a wall at z = 0, at eye height: its two eyes' images
  // are apart by the parallax of that depth.
  SceneDefinition scene = probe("stereo-probe");
  scene.meshes.push_back(make_quad(1.0f, 1.0f));
  scene.instances.push_back({0, 0, std::nullopt, placed({0.0, 1.6, -1.0}, {0.1, 0.1, 1.0})});
  return scene;
}

SceneDefinition corner_probe() {
  // Two long bars, one level and one tilted, in front of a CAVE's front wall and
  // long enough to be seen through the side walls too: at a wall corner, each bar
  // must continue from one wall's image into the other's.
  SceneDefinition scene = probe("corner-probe");
  scene.meshes.push_back(make_box(glm::vec3(1.0f)));
  scene.instances.push_back({0, 0, std::nullopt, placed({0.0, 1.2, -1.0}, {4.8, 0.08, 0.02})});
  scene.instances.push_back({0, 0, std::nullopt, placed({0.0, 1.9, -1.2}, {4.8, 0.05, 0.02}, 0.2)});
  return scene;
}

struct Entry {
  std::string_view name;
  SceneDefinition (*make)();
};

constexpr std::array kScenes{
    Entry{"cubes", cubes},
    Entry{"many-lights", [] { return many_lights(20); }},
    Entry{"depth-stack", depth_stack},
    Entry{"moving-square", moving_square},
    Entry{"scrolling-stripes", scrolling_stripes},
    Entry{"pinball", pinball},
    Entry{"cubes-backdrop", cubes_backdrop},
    Entry{"many-lights-50", [] { return many_lights(50); }},
    Entry{"many-lights-100", [] { return many_lights(100); }},
    // the up-conversion set
    Entry{"cube-fast-rotation", cube_fast_rotation},
    Entry{"cube-slow-rotation", cube_slow_rotation},
    Entry{"cube-zoom", cube_zoom},
    Entry{"pyramid-fast-rotation", pyramid_fast_rotation},
    Entry{"pyramid-slow-rotation", pyramid_slow_rotation},
    Entry{"wheel-rotation", wheel_rotation},
    Entry{"wheel-in-out", wheel_in_out},
    Entry{"falling-ring", falling_ring},
    // test probes
    Entry{"stereo-probe", stereo_probe},
    Entry{"corner-probe", corner_probe},
};

constexpr std::array<std::string_view, kScenes.size()> kNames = [] {
  std::array<std::string_view, kScenes.size()> names{};
  for (std::size_t i = 0; i < kScenes.size(); ++i) names[i] = kScenes[i].name;
  return names;
}();

}  // namespace

std::span<const std::string_view> builtin_scene_names() { return kNames; }

bool is_builtin_scene(std::string_view name) { return std::find(kNames.begin(), kNames.end(), name) != kNames.end(); }

Result<SceneDefinition> builtin_scene(std::string_view name) {
  for (const Entry& e : kScenes) {
    if (e.name == name) return e.make();
  }
  return Error{"unknown built-in scene '" + std::string(name) + "'"};
}

}  // namespace optique::scene
