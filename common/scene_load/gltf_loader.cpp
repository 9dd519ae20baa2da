#include "scene_load/gltf_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "util/finite.h"

namespace optique::scene {
namespace {

// glTF point lights are in candela; our scenes are not photometric: a light's
// irradiance is colour·intensity / r² in the renderer's own units, and the
// built-in scenes use intensities of about 1 to 3. So 100 cd ↦ 1.
constexpr double kCandelaToIntensity = 1.0 / 100.0;

}  // namespace

using gltf::decompose;
using gltf::finite;
using gltf::Interpolation;
using gltf::Link;
using gltf::reproduces;
using gltf::Sampler;
using gltf::Track;
using util::finite;

SceneDefinition Loader::build() {
  check_version();
  check_skins();
  read_animations();
  walk_scene();
  read_links();
  SceneDefinition scene;
  scene.name = scene_name();
  add_instances(scene);
  add_lights(scene);
  return scene;
}

void Loader::check_version() const {
  const auto& version = model_.asset.version;
  if (!version.starts_with("2.")) fail("glTF version '" + version + "' is not supported (2.x only)");
}

void Loader::check_skins() const {
  if (!model_.skins.empty()) fail("skinned meshes are not supported (the file has skins)");
  for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
    if (model_.nodes[i].skin >= 0) fail("skinned meshes are not supported (" + node_label(i) + " has a skin)");
  }
}

void Loader::read_animations() {
  for (std::size_t a = 0; a < model_.animations.size(); ++a) {
    const auto& animation = model_.animations[a];
    const std::string animation_label = labelled("animation", a, animation.name);
    for (std::size_t c = 0; c < animation.channels.size(); ++c) {
      const auto& channel = animation.channels[c];
      const std::string label = animation_label + " channel " + std::to_string(c);
      if (channel.target_path == "weights") fail(label + ": morph targets are not supported (it animates weights)");
      if (channel.target_path != "translation" && channel.target_path != "rotation" && channel.target_path != "scale") {
        fail(label + ": animating '" + channel.target_path + "' is not supported");
      }
      if (channel.target_node < 0) {
        warn(label + " has no target node; ignored");
        continue;
      }
      if (static_cast<std::size_t>(channel.target_node) >= model_.nodes.size()) {
        fail(label + ": target node " + std::to_string(channel.target_node) + " is out of range");
      }
      if (channel.sampler < 0 || static_cast<std::size_t>(channel.sampler) >= animation.samplers.size()) {
        fail(label + ": sampler " + std::to_string(channel.sampler) + " is out of range");
      }
      const auto& source = animation.samplers[static_cast<std::size_t>(channel.sampler)];
      const std::string sampler_label = animation_label + " sampler " + std::to_string(channel.sampler);
      Sampler sampler = read_sampler(source, sampler_label, channel.target_path == "rotation");
      duration_ = std::max(duration_, sampler.times.back());

      auto& tracks = channels_[static_cast<std::size_t>(channel.target_node)];
      auto& slot = channel.target_path == "translation" ? tracks.translation
                   : channel.target_path == "rotation"  ? tracks.rotation
                                                        : tracks.scale;
      if (slot) {
        warn(node_label(static_cast<std::size_t>(channel.target_node)) + ": several channels animate its " +
             channel.target_path + "; the first one is used");
        continue;
      }
      slot = std::move(sampler);
    }
  }
}

Sampler Loader::read_sampler(const tinygltf::AnimationSampler& source, const std::string& label, bool rotation) const {
  Sampler sampler;
  sampler.rotation = rotation;
  if (source.interpolation == "LINEAR" || source.interpolation.empty()) {
    sampler.interpolation = Interpolation::kLinear;
  } else if (source.interpolation == "STEP") {
    sampler.interpolation = Interpolation::kStep;
  } else if (source.interpolation == "CUBICSPLINE") {
    sampler.interpolation = Interpolation::kCubicSpline;
  } else {
    fail(label + ": interpolation '" + source.interpolation + "' is not supported");
  }
  sampler.times = data_.read_floats(source.input, label + " input", TINYGLTF_TYPE_SCALAR);
  if (sampler.times.empty()) fail(label + ": the input has no key times");
  for (std::size_t k = 1; k < sampler.times.size(); ++k) {
    if (!(sampler.times[k] > sampler.times[k - 1])) {
      fail(label + ": input times must increase (key " + std::to_string(k) + ")");
    }
  }
  sampler.values =
      data_.read_floats(source.output, label + " output", rotation ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3,
                        /*normalized_ok=*/rotation);
  const std::size_t per_key = sampler.interpolation == Interpolation::kCubicSpline ? 3 : 1;
  const std::size_t expected = sampler.times.size() * per_key;
  if (sampler.values.size() != expected * sampler.width()) {
    fail(label + ": the output has " + std::to_string(sampler.values.size() / sampler.width()) + " elements where " +
         std::to_string(expected) + " were expected");
  }
  if (rotation) {
    // Key values must be unit quaternions; make them exactly so (tangents stay).
    for (std::size_t k = 0; k < sampler.times.size(); ++k) {
      double* q = sampler.values.data() + (k * per_key + (per_key == 3 ? 1 : 0)) * 4;
      const double length = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(length > 1e-6) || !std::isfinite(length)) {
        fail(label + ": rotation key " + std::to_string(k) + " is not a unit quaternion");
      }
      for (int i = 0; i < 4; ++i) q[i] /= length;
    }
  }
  return sampler;
}

void Loader::walk_scene() {
  std::vector<int> roots;
  if (model_.defaultScene >= 0 || !model_.scenes.empty()) {
    const int chosen = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (static_cast<std::size_t>(chosen) >= model_.scenes.size()) {
      fail("scene " + std::to_string(chosen) + " is out of range");
    }
    scene_index_ = chosen;
    roots = model_.scenes[static_cast<std::size_t>(chosen)].nodes;
  } else {
    std::vector<bool> is_child(model_.nodes.size(), false);
    for (const auto& node : model_.nodes) {
      for (int child : node.children) {
        if (child >= 0 && static_cast<std::size_t>(child) < model_.nodes.size()) {
          is_child[static_cast<std::size_t>(child)] = true;
        }
      }
    }
    for (std::size_t i = 0; i < model_.nodes.size(); ++i) {
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
    }
    if (!roots.empty()) warn("the file has no scene; drawing every root node");
  }

  parent_.assign(model_.nodes.size(), -1);
  std::vector<bool> seen(model_.nodes.size(), false);
  // Depth first, parents before children, without recursion.
  std::vector<std::pair<int, int>> stack;  // node, parent
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, -1);
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    if (node < 0 || static_cast<std::size_t>(node) >= model_.nodes.size()) {
      fail("node " + std::to_string(node) + " is out of range" +
           (parent >= 0 ? " (a child of " + node_label(static_cast<std::size_t>(parent)) + ")" : ""));
    }
    const auto index = static_cast<std::size_t>(node);
    if (seen[index]) {
      fail(node_label(index) + " is reached twice: the node hierarchy has a cycle or a shared child");
    }
    seen[index] = true;
    parent_[index] = parent;
    order_.push_back(index);
    const auto& children = model_.nodes[index].children;
    for (auto it = children.rbegin(); it != children.rend(); ++it) stack.emplace_back(*it, node);
  }

  animated_.assign(model_.nodes.size(), false);
  for (std::size_t index : order_) {
    const bool targeted = channels_.contains(index);
    animated_[index] = targeted || (parent_[index] >= 0 && animated_[static_cast<std::size_t>(parent_[index])]);
  }
}

std::vector<double> Loader::checked(const std::vector<double>& values, std::size_t size, const std::string& what,
                                    std::size_t node) const {
  if (values.size() != size) {
    fail(node_label(node) + ": " + what + " must have " + std::to_string(size) + " numbers, not " +
         std::to_string(values.size()));
  }
  for (double v : values) {
    if (!std::isfinite(v)) fail(node_label(node) + ": " + what + " is not finite");
  }
  return values;
}

// Every node's local transform; the animated ones with their tracks.
void Loader::read_links() {
  links_.resize(model_.nodes.size());
  world0_.assign(model_.nodes.size(), glm::dmat4(1.0));
  for (std::size_t index : order_) {
    const auto& node = model_.nodes[index];
    Link& link = links_[index];
    const auto tracks = channels_.find(index);
    if (!node.matrix.empty()) {
      if (tracks != channels_.end()) {
        fail(node_label(index) +
             " has a matrix and is animated; glTF allows only translation, rotation and scale "
             "on animated nodes");
      }
      const auto m = checked(node.matrix, 16, "matrix", index);
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) link.fixed[c][r] = m[static_cast<std::size_t>(4 * c + r)];
      }
    } else {
      if (!node.translation.empty()) {
        const auto t = checked(node.translation, 3, "translation", index);
        link.translation = {t[0], t[1], t[2]};
      }
      if (!node.rotation.empty()) {
        const auto q = checked(node.rotation, 4, "rotation", index);
        const glm::dquat rotation(q[3], q[0], q[1], q[2]);
        const double length = glm::length(rotation);
        if (!(length > 1e-6)) fail(node_label(index) + ": rotation is not a unit quaternion");
        link.rotation = rotation / length;
      }
      if (!node.scale.empty()) {
        const auto s = checked(node.scale, 3, "scale", index);
        link.scale = {s[0], s[1], s[2]};
      }
      link.fixed = glm::translate(glm::dmat4(1.0), link.translation) * glm::mat4_cast(link.rotation) *
                   glm::scale(glm::dmat4(1.0), link.scale);
      if (tracks != channels_.end()) {
        link.animated = true;
        link.translation_track = tracks->second.translation;
        link.rotation_track = tracks->second.rotation;
        link.scale_track = tracks->second.scale;
      }
    }
    const glm::dmat4 parent = parent_[index] >= 0 ? world0_[static_cast<std::size_t>(parent_[index])] : glm::dmat4(1.0);
    world0_[index] = parent * link.local_at(0.0);
    if (!finite(world0_[index])) fail(node_label(index) + ": its world transform is not finite");
  }
}

// The track of an animated node: its nearest static ancestor's world matrix and
// the links from the topmost animated ancestor down to it.
Track Loader::track_of(std::size_t index) const {
  Track track;
  track.duration = duration_;
  std::vector<std::size_t> chain;
  int at = static_cast<int>(index);
  while (at >= 0 && animated_[static_cast<std::size_t>(at)]) {
    chain.push_back(static_cast<std::size_t>(at));
    at = parent_[static_cast<std::size_t>(at)];
  }
  if (at >= 0) track.base = world0_[static_cast<std::size_t>(at)];
  for (auto it = chain.rbegin(); it != chain.rend(); ++it) track.links.push_back(links_[*it]);

  // Check the pose at every key time and half way between them: finite, and
  // reproducing the world matrix (no shear, which a pose cannot express).
  std::vector<double> times{0.0};
  for (const auto& link : track.links) link.key_times(times);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  const std::size_t keys = times.size();
  for (std::size_t k = 1; k < keys; ++k) times.push_back(0.5 * (times[k - 1] + times[k]));
  for (double t : times) {
    const double local = track.wrap(t);
    const glm::dmat4 world = track.world_at(local);
    if (!finite(world)) {
      fail(node_label(index) + ": its world transform at t = " + std::to_string(local) + " s is not finite");
    }
    const Pose pose = decompose(world);
    if (!finite(pose) || !reproduces(pose, world)) {
      fail(node_label(index) + " is animated, but its world transform at t = " + std::to_string(local) +
           " s has shear (a non-uniformly scaled parent with a rotated child) or is not affine, which an "
           "animated object's pose cannot express");
    }
  }
  track.fallback = decompose(track.world_at(0.0));
  return track;
}

std::string Loader::scene_name() const {
  if (scene_index_ >= 0) {
    const auto& name = model_.scenes[static_cast<std::size_t>(scene_index_)].name;
    if (!name.empty()) return name;
  }
  return std::filesystem::path(path_).stem().string();
}

void Loader::add_instances(SceneDefinition& scene) {
  for (std::size_t index : order_) {
    const auto& node = model_.nodes[index];
    if (node.mesh < 0) continue;
    const auto parts = parts_of(static_cast<std::size_t>(node.mesh), index);
    if (parts.empty()) continue;
    if (animated_[index]) {
      const auto id = static_cast<std::uint32_t>(scene.objects.size() + 1);
      Track track = track_of(index);
      const std::string name = node.name.empty() ? "node " + std::to_string(index) : node.name;
      scene.objects.push_back({id, name, [track = std::move(track)](double t) { return track.pose_at(t); }});
      for (const auto& part : parts) scene.instances.push_back({part.mesh, part.material, id, glm::dmat4(1.0)});
    } else {
      for (const auto& part : parts) {
        scene.instances.push_back({part.mesh, part.material, std::nullopt, world0_[index]});
      }
    }
  }
  scene.meshes = std::move(meshes_);
  scene.materials = std::move(materials_);
  scene.textures = std::move(textures_);
}

void Loader::add_lights(SceneDefinition& scene) {
  for (std::size_t index : order_) {
    const auto& node = model_.nodes[index];
    const auto extension = node.extensions.find("KHR_lights_punctual");
    if (extension == node.extensions.end()) continue;
    if (!extension->second.IsObject() || !extension->second.Has("light") || !extension->second.Get("light").IsInt()) {
      fail(node_label(index) + ": KHR_lights_punctual must name a light by its index");
    }
    const int light_index = extension->second.Get("light").GetNumberAsInt();
    if (light_index < 0 || static_cast<std::size_t>(light_index) >= model_.lights.size()) {
      fail(node_label(index) + ": light " + std::to_string(light_index) + " is out of range");
    }
    const auto& light = model_.lights[static_cast<std::size_t>(light_index)];
    const std::string label = labelled("light", static_cast<std::size_t>(light_index), light.name);
    if (light.type != "point") {
      warn(label + " (on " + node_label(index) + "): " + light.type + " lights are not supported; skipped");
      continue;
    }
    PointLight out;
    out.position = glm::dvec3(world0_[index][3]);
    if (!light.color.empty()) {
      if (light.color.size() != 3) fail(label + ": color must have 3 numbers");
      for (int c = 0; c < 3; ++c) {
        out.colour[c] = std::max(0.0f, to_float(light.color[static_cast<std::size_t>(c)], label + ": color"));
      }
    }
    out.intensity = std::max(0.0f, to_float(light.intensity * kCandelaToIntensity, label + ": intensity"));
    if (animated_[index]) warn(label + " is on an animated node; it stays where it is at t = 0");
    scene.lights.push_back(out);
  }
}

}  // namespace optique::scene
