#pragma once
// The live scene applications edit (proto/optique/session.proto): the assets
// loaded, and the instances of them, each with its parent, placement,
// visibility and material factors. A transaction is checked edit by edit
// against the scene as the edits before it left it, and lands whole or not at
// all: the first edit that cannot be applied is named with its field and
// why, and the scene is as it was. No IO: the master's session shell decodes
// the bytes, hands the transaction here, and reads the instances at each
// frame's beginning, so that a transaction received before frame k begins is
// in frame k.

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "config/installation.h"
#include "optique/session.pb.h"
#include "scene/definition.h"
#include "scene/state.h"

namespace optique::master {

// An instance's own clock for its asset's animations (SetAnimation).
struct AnimationClock {
  bool playing = true;
  double position = 0.0;     // seconds into the animations at frame `anchor`
  std::uint64_t anchor = 0;  // the frame it was set for
  // Where it is at `frame` (not before `anchor`), frames `period` seconds apart.
  [[nodiscard]] double at(std::uint64_t frame, double period) const;
  friend bool operator==(const AnimationClock&, const AnimationClock&) = default;
};

struct Instance {
  std::string asset;
  std::string parent;  // empty: the world
  scene::Pose pose;    // relative to the parent
  bool visible = true;
  glm::dvec4 base_color{1.0};               // multiplies the asset's base colour
  glm::dvec3 emissive{1.0};                 // multiplies the asset's emissive colour
  std::optional<AnimationClock> animation;  // none: the scene's time
  friend bool operator==(const Instance&, const Instance&) = default;
};

struct LiveSceneLimits {
  std::size_t max_instances = 100000;
  std::size_t max_edits_per_frame = 100000;               // over every transaction of a frame
  std::size_t max_depth = scene::kMaxInstanceDepth;       // instances above an instance, the world not counted
  std::size_t max_point_lights = scene::kMaxAddedLights;  // lights added (SetPointLight), at most kMaxAddedLights
};

// The limits master.api sets (none: the defaults, as for a replay without it).
[[nodiscard]] LiveSceneLimits live_scene_limits(const std::optional<config::ApiServer>& api);

// Why a transaction was refused: its first edit that could not be applied.
struct Refusal {
  std::size_t edit = 0;
  std::string field;   // "edits[3].transform.scale[1]"
  std::string reason;  // "must be in [1e-4, 1e4] (got 0)"
};

// The navigation as applications set it (SetNavigation), and how many times
// they have: a set to where it already was still brings a flown viewer back.
struct NavigationSet {
  scene::Pose pose;  // world ← installation; a uniform scale
  std::uint64_t sets = 0;
  friend bool operator==(const NavigationSet&, const NavigationSet&) = default;
};

class LiveScene {
 public:
  // `frame_period`: seconds from one frame's simulation time to the next
  // (clock::frame_period), by which an instance's animation clock plays.
  explicit LiveScene(LiveSceneLimits limits = {}, double frame_period = 1.0 / 60.0)
      : limits_(limits), frame_period_(frame_period) {}
  // The live scene of an installation whose scene is `scene`, at
  // `frame_rate` Hz: its one asset the scene itself (by its asset id), its
  // point lights switchable.
  [[nodiscard]] static LiveScene of(const scene::SceneDefinition& scene, LiveSceneLimits limits, double frame_rate);
  [[nodiscard]] double frame_period() const { return frame_period_; }

  // An asset the nodes can draw (loaded and shipped by the scene transfer).
  // `animated`: an asset an application loaded that has animations: each
  // instance of it plays them on its own clock from the frame it is created
  // in (the scene's own asset plays with the scene's time).
  void add_asset(const std::string& id, bool animated = false) {
    assets_.insert(id);
    loading_.erase(id);
    if (animated) animated_.insert(id);
  }
  [[nodiscard]] bool has_asset(const std::string& id) const { return assets_.count(id) != 0; }
  [[nodiscard]] const std::set<std::string>& assets() const { return assets_; }
  // An asset being loaded (LoadAsset) and not yet on every node: an instance
  // of it is refused as "still loading", and its id is taken.
  void set_loading(const std::string& id, bool loading) {
    if (loading) {
      loading_.insert(id);
    } else {
      loading_.erase(id);
    }
  }
  [[nodiscard]] bool is_loading(const std::string& id) const { return loading_.count(id) != 0; }

  // Applies every edit, or none and says which and why; `frame` is the frame
  // it is in (where an animation played, paused or sought starts from there).
  [[nodiscard]] std::optional<Refusal> apply(const session::Transaction& transaction, std::uint64_t frame);
  // A new run of the master begins, at frame 0, after the journal of the runs
  // before was applied, the last of its transactions in frame `last`: each
  // animation clock goes on from where it was then.
  void begin_run(std::uint64_t last);
  // A new frame: the budget of edits starts again.
  void begin_frame() { edits_this_frame_ = 0; }
  // The ids of the instances set or removed since the last call (a
  // transaction refused may leave some that did not change): what the master
  // stages to the nodes between rounds (wire.proto's StagedEdit).
  [[nodiscard]] std::set<std::string> take_edited() { return std::exchange(edited_, {}); }
  // The instances whose animation clock plays: their state changes every frame.
  [[nodiscard]] const std::set<std::string>& playing() const { return playing_; }

  // How many point lights the scene has (SwitchLight's bound).
  void set_light_count(std::size_t count) { light_count_ = count; }
  [[nodiscard]] std::size_t light_count() const { return light_count_; }

  using Instances = std::map<std::string, Instance>;
  [[nodiscard]] const Instances& instances() const { return instances_; }
  [[nodiscard]] const NavigationSet& navigation() const { return navigation_; }
  // The lights applications switched: index → on.
  [[nodiscard]] const std::map<std::uint32_t, bool>& light_switches() const { return light_switches_; }
  // The point lights applications added, by index (from light_count() on).
  [[nodiscard]] const std::map<std::uint32_t, scene::PointLightState>& point_lights() const { return point_lights_; }
  [[nodiscard]] std::size_t max_point_lights() const { return limits_.max_point_lights; }
  [[nodiscard]] const std::set<std::string>& children(const std::string& parent) const;

 private:
  class Edits;  // one transaction's edits with their undo (live_scene.cpp)

  // Sets or (nullopt) removes an instance, keeping the children index true.
  void put(const std::string& id, std::optional<Instance> instance);
  // Sets the instance at `at` to `instance`, under the same parent: put's
  // work without its searches (a transaction that moves a thousand).
  void replace(Instances::iterator at, Instance instance);
  // Notes an edit of `id`, playing or not after it: what put and replace share.
  void note_edit(const std::string& id, bool was_playing, const Instance* now);

  LiveSceneLimits limits_;
  double frame_period_;
  std::set<std::string> assets_;
  std::set<std::string> loading_;
  std::set<std::string> animated_;  // of assets_
  Instances instances_;
  std::map<std::string, std::set<std::string>> children_;  // parent → its children; "" → the world's
  std::size_t edits_this_frame_ = 0;
  std::set<std::string> edited_;
  std::set<std::string> playing_;
  std::size_t light_count_ = 0;
  NavigationSet navigation_;
  std::map<std::uint32_t, bool> light_switches_;
  std::map<std::uint32_t, scene::PointLightState> point_lights_;
};

// A pose as the session writes it (InstanceView, SceneContents, HeadShown):
// every field given, the scale as three numbers.
void to_transform(const scene::Pose& pose, session::Transform& t);

// The live scene as an application reads it (session::ReadScene), as frame
// `frame` will show it.
[[nodiscard]] session::SceneContents scene_contents(const LiveScene& live, std::uint64_t frame);

// The live scene into the state frame `frame` shows (scene/state.h): the
// instances, each at its pose, the same now and at the next frame time, as an
// edit between them is not known yet, and its animation clock's times; the
// lights applications switched, over the config's switches, and the lights
// they added; the navigation
// applications set (the flystick's, if any, comes after: master/navigation.h).
void put_live(const LiveScene& live, std::uint64_t frame, scene::SceneState& state);
// All put_live puts but the instances: the lights and the navigation.
void put_live_lights(const LiveScene& live, scene::SceneState& state);
// One of the live scene's instances as put_live puts it.
[[nodiscard]] scene::InstanceState instance_state(const LiveScene& live, const Instance& instance, std::uint64_t frame);

}  // namespace optique::master
