#pragma once
// The scene state every node must agree on: dynamic objects, each with its pose at
// the frame time and at the next frame time, the viewer's eyes and head at both times, where
// the installation is in the world (the navigation), and which of the scene's point lights
// are switched off.
// A snapshot on join, then per frame only what changed; a hash both sides compare.

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "optique/wire.pb.h"
#include "util/result.h"

namespace optique::scene {

struct Pose {
  glm::dvec3 position{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
  glm::dvec3 scale{1.0};

  bool operator==(const Pose&) const = default;
};

struct ObjectState {
  Pose now;
  Pose next;

  bool operator==(const ObjectState&) const = default;
};

// Where an instance's asset's animations are, in seconds into them, at the
// frame time and at the next: the instance's own clock (an application's
// SetAnimation) in place of the scene's time.
struct AnimationTimes {
  double now = 0.0;
  double next = 0.0;

  bool operator==(const AnimationTimes&) const = default;
};
// The most seconds into its animations an instance's clock may be (about 30
// years: a clock that plays for the life of an installation stays below it).
inline constexpr double kMaxAnimationSeconds = 1e9;

// An instance of an asset an application placed (master/session/live_scene.h).
struct InstanceState {
  std::string asset;
  std::string parent;  // empty: the world; its pose is relative to the parent's
  ObjectState pose;
  bool visible = true;
  glm::dvec4 base_color{1.0};               // multiplies the asset's base colour
  glm::dvec3 emissive{1.0};                 // multiplies the asset's emissive colour
  std::optional<AnimationTimes> animation;  // none: the scene's own time

  bool operator==(const InstanceState&) const = default;
};

// The most instances a chain of parents holds (the world not counted): what a
// node accepts from the wire, and what the master's live scene allows.
inline constexpr std::size_t kMaxInstanceDepth = 64;
// The most assets applications may load (LoadAsset) into one live scene: what
// a node takes in its welcome.
inline constexpr std::size_t kMaxAssets = 256;
inline constexpr std::size_t kMaxInstanceIdLength = 64;
inline constexpr double kMaxEmissiveFactor = 1e3;

// 1 to kMaxInstanceIdLength letters, digits, '-', '_' or '.': an id safe in a
// log, a file name and JSON as it is.
[[nodiscard]] bool is_instance_id(std::string_view id);

// A point light an application added (master.api's SetPointLight), in the
// world as the scene's own lights are.
struct PointLightState {
  glm::dvec3 position{0.0};  // world metres
  glm::dvec3 colour{1.0};    // linear
  double intensity = 1.0;    // irradiance = colour·intensity / r²
  bool operator==(const PointLightState&) const = default;
};

// What a node takes from the wire, and what the master's live scene allows:
// at most kMaxAddedLights lights added, each index below kMaxLightIndex (the
// scene's own lights come first: at most 2^16 of them), the colour's channels
// in [0, kMaxLightColour], the intensity in [0, kMaxLightIntensity], the
// position within ±kMaxLightDistance.
inline constexpr std::size_t kMaxAddedLights = 64;
inline constexpr std::uint32_t kMaxLightIndex = (1u << 16) + kMaxAddedLights;
inline constexpr double kMaxLightColour = 1e3;
inline constexpr double kMaxLightIntensity = 1e6;
inline constexpr double kMaxLightDistance = 1e6;

struct SceneState {
  std::map<std::uint32_t, ObjectState> objects;
  glm::dvec3 eye_now{0.0};  // the centre of the eyes
  glm::dvec3 eye_next{0.0};
  // The head's turn from rest (identity but for a tracked head): it turns the
  // viewer's head_right, the axis from the left eye to the right.
  glm::dquat head_now{1.0, 0.0, 0.0, 0.0};
  glm::dquat head_next{1.0, 0.0, 0.0, 0.0};
  // The navigation: world ← installation (the room's screens, eyes and tracker
  // are in the installation's space; the scene is in the world's). Identity
  // but for a viewer who travels (viewer.navigation, or an application's
  // SetNavigation); a rigid move and a uniform scale.
  ObjectState navigation;
  // Indices into the scene's lights. A light that goes dark costs nothing: no node
  // draws it, and the automatic light split shares out only the others.
  std::set<std::uint32_t> lights_off;
  // By id: the live scene's instances, as the frame shows them.
  std::map<std::string, InstanceState> instances;
  // By index (after the scene's own): the point lights applications added.
  // lights_off switches them as it does the scene's.
  std::map<std::uint32_t, PointLightState> point_lights;

  bool operator==(const SceneState&) const = default;
};

// The centre of the eyes and the head's turn `fraction` of a frame after the
// frame time (linear, and spherical between the turns).
[[nodiscard]] glm::dvec3 eyes_at(const SceneState& state, double fraction);
[[nodiscard]] glm::dquat head_at(const SceneState& state, double fraction);

// The navigation's scale: uniform, and within these bounds (the wire's check).
inline constexpr double kLeastNavigationScale = 1e-4;
inline constexpr double kMostNavigationScale = 1e4;

// A 64-bit hash of a canonical encoding (ids in order, the bits of every
// double, words of eight bytes the first lowest), so equal states hash equally
// on every machine. The instances count in it as the sum (mod 2^64) of each
// one's own hash: a delta that changes a few of thousands is followed by
// hashing those few again (apply_delta with InstancesHash), not all of them.
[[nodiscard]] std::uint64_t state_hash(const SceneState& state);

struct InstancesHash {
  std::uint64_t sum = 0;
  bool operator==(const InstancesHash&) const = default;
};
[[nodiscard]] std::uint64_t instance_hash(const std::string& id, const InstanceState& instance);
[[nodiscard]] InstancesHash instances_hash(const SceneState& state);
// state_hash(state) with the instances' part known: O(what is not an instance).
[[nodiscard]] std::uint64_t state_hash(const SceneState& state, InstancesHash instances);

[[nodiscard]] wire::Snapshot to_snapshot(const SceneState& state);
[[nodiscard]] Result<SceneState> from_snapshot(const wire::Snapshot& snapshot);

// What changed from `before` to `after`; without `instances`, all but the
// instances (the master follows them itself: make_instance_delta).
[[nodiscard]] wire::StateDelta make_delta(const SceneState& before, const SceneState& after, bool instances = true);

// Applies `delta` to `state`, or leaves it untouched and says what is wrong
// (non-finite numbers, removing an object that does not exist, switching off a
// light that is off or on one that is on, an instance whose parent is missing,
// is itself or under it, or deeper than kMaxInstanceDepth; a point light out of
// bounds, removed when it is not there, or more than kMaxAddedLights of them).
[[nodiscard]] Result<void> apply_delta(SceneState& state, const wire::StateDelta& delta);
// The same, keeping `instances` (instances_hash(state) before) true for the
// state after; untouched when the delta is refused.
[[nodiscard]] Result<void> apply_delta(SceneState& state, const wire::StateDelta& delta, InstancesHash& instances);

// The instances `after` names, as a delta from `before`: each id with its
// state then, or none where it is removed (where `before` has it). Every other
// part of the state is left out: the master's staged edits (wire.proto's
// StagedEdit).
[[nodiscard]] wire::StateDelta make_instance_delta(const SceneState& before,
                                                   const std::map<std::string, std::optional<InstanceState>>& after);

}  // namespace optique::scene
