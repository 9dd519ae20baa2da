#include "master/session/live_scene.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "clock/clock.h"
#include "util/id_text.h"
#include "util/number_text.h"

namespace optique::master {
namespace {

using util::number_text;

constexpr double kMaxPosition = 1e6;  // metres from the origin: a world larger than any room, short of float trouble
constexpr double kMinScale = 1e-4;
constexpr double kMaxScale = 1e4;
constexpr double kMaxSeek = 1e6;  // seconds into an asset's animations: eleven days

// What is wrong, at a field relative to the edit ("transform.scale[1]").
struct Wrong {
  std::string field;
  std::string reason;
};
using Check = std::optional<Wrong>;

Check id_problem(const std::string& field, const std::string& id) {
  if (id.empty()) return Wrong{field, "is needed"};
  if (id.size() > scene::kMaxInstanceIdLength) {
    return Wrong{field, "is " + std::to_string(id.size()) + " characters long; at most " +
                            std::to_string(scene::kMaxInstanceIdLength)};
  }
  if (!scene::is_instance_id(id)) return Wrong{field, "may only use letters, digits, '-', '_' and '.'"};
  return std::nullopt;
}

Check numbers_problem(const std::string& field, const google::protobuf::RepeatedField<double>& v, double low,
                      double high) {
  for (int i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i]) || v[i] < low || v[i] > high) {
      return Wrong{field + "[" + std::to_string(i) + "]",
                   "must be in [" + number_text(low) + ", " + number_text(high) + "] (got " + number_text(v[i]) + ")"};
    }
  }
  return std::nullopt;
}

Check count_problem(const std::string& field, int got, std::initializer_list<int> allowed, const char* what) {
  for (int n : allowed) {
    if (got == n) return std::nullopt;
  }
  return Wrong{field, std::string("must be ") + what + " (got " + std::to_string(got) + " numbers)"};
}

// What the transform gives, over `pose`.
Check read_transform(const session::Transform& t, scene::Pose& pose) {
  if (!t.position().empty()) {
    if (auto wrong = count_problem("transform.position", t.position_size(), {3}, "[x, y, z]")) return wrong;
    if (auto wrong = numbers_problem("transform.position", t.position(), -kMaxPosition, kMaxPosition)) return wrong;
    pose.position = {t.position(0), t.position(1), t.position(2)};
  }
  if (!t.rotation().empty()) {
    if (auto wrong = count_problem("transform.rotation", t.rotation_size(), {4}, "a quaternion [w, x, y, z]")) {
      return wrong;
    }
    if (auto wrong = numbers_problem("transform.rotation", t.rotation(), -1e6, 1e6)) return wrong;
    const glm::dquat q(t.rotation(0), t.rotation(1), t.rotation(2), t.rotation(3));
    const double length = glm::length(q);
    if (!(length > 1e-9)) return Wrong{"transform.rotation", "has length 0: it is no rotation"};
    pose.rotation = q / length;
  }
  if (!t.scale().empty()) {
    if (auto wrong = count_problem("transform.scale", t.scale_size(), {1, 3}, "[x, y, z] or [s]")) return wrong;
    if (auto wrong = numbers_problem("transform.scale", t.scale(), kMinScale, kMaxScale)) return wrong;
    pose.scale = t.scale_size() == 1 ? glm::dvec3(t.scale(0)) : glm::dvec3(t.scale(0), t.scale(1), t.scale(2));
  }
  return std::nullopt;
}

}  // namespace

void to_transform(const scene::Pose& pose, session::Transform& t) {
  for (int i = 0; i < 3; ++i) t.add_position(pose.position[i]);
  for (double q : {pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z}) t.add_rotation(q);
  for (int i = 0; i < 3; ++i) t.add_scale(pose.scale[i]);
}

// One transaction's edits, applied to the scene as they come, with what each
// instance was before its first change, to put back if a later edit fails.
class LiveScene::Edits {
 public:
  Edits(LiveScene& scene, std::uint64_t frame) : scene_(scene), frame_(frame) {}

  // Applies one edit; what is wrong is named from the edit ("create.asset").
  Check apply(const session::Edit& edit) {
    const auto named = [](const char* kind, Check wrong) -> Check {
      if (wrong) wrong->field = std::string(kind) + "." + wrong->field;
      return wrong;
    };
    switch (edit.edit_case()) {
      case session::Edit::kCreate:
        return named("create", create(edit.create()));
      case session::Edit::kTransform:
        return named("transform", transform(edit.transform()));
      case session::Edit::kParent:
        return named("parent", parent(edit.parent()));
      case session::Edit::kVisible:
        return named("visible", visible(edit.visible()));
      case session::Edit::kRemove:
        return named("remove", remove(edit.remove()));
      case session::Edit::kFactors:
        return named("factors", factors(edit.factors()));
      case session::Edit::kNavigation:
        return named("navigation", navigation(edit.navigation()));
      case session::Edit::kLight:
        return named("light", light(edit.light()));
      case session::Edit::kAnimation:
        return named("animation", animation(edit.animation()));
      case session::Edit::kPointLight:
        return named("point_light", point_light(edit.point_light()));
      case session::Edit::kRemovePointLight:
        return named("remove_point_light", remove_point_light(edit.remove_point_light()));
      case session::Edit::EDIT_NOT_SET:
        break;
    }
    return Wrong{"", "is empty or of a kind this master does not know"};
  }

  // Puts every changed instance back as it was, the last change first, and
  // the navigation, the light switches and the lights added.
  void undo() {
    for (auto it = before_.rbegin(); it != before_.rend(); ++it) scene_.put(it->first, it->second);
    before_.clear();
    if (navigation_before_) scene_.navigation_ = *navigation_before_;
    if (lights_before_) scene_.light_switches_ = std::move(*lights_before_);
    if (point_lights_before_) scene_.point_lights_ = std::move(*point_lights_before_);
  }

 private:
  void put(const std::string& id, std::optional<Instance> instance) {
    const auto now = scene_.instances_.find(id);
    remember(id, now == scene_.instances_.end() ? nullptr : &now->second);
    scene_.put(id, std::move(instance));
  }

  // Keeps `id` as it is (`now`; none: not there) to put back, if this is the
  // transaction's first change of it.
  void remember(const std::string& id, const Instance* now) {
    if (touched_.insert(id).second) before_.emplace_back(id, now == nullptr ? std::nullopt : std::optional(*now));
  }

  // The instance `id` names (at `field`), or why there is none.
  Check existing(const std::string& field, const std::string& id, Instances::iterator& at) const {
    if (auto wrong = id_problem(field, id)) return wrong;
    at = scene_.instances_.find(id);
    if (at == scene_.instances_.end()) return Wrong{field, "no instance '" + id + "'"};
    return std::nullopt;
  }

  // The instance `id` names, changed by `change` (which says what is wrong
  // instead, leaving it as it was).
  template <class Change>
  Check modify(const std::string& id, const Change& change) {
    Instances::iterator at;
    if (auto wrong = existing("instance", id, at)) return wrong;
    Instance changed = at->second;
    if (auto wrong = change(changed)) return wrong;
    if (changed.parent != at->second.parent) {
      put(id, std::move(changed));
      return std::nullopt;
    }
    // Found once, kept as it was once: a transaction that moves a thousand
    // instances searched for each one five times.
    remember(id, &at->second);
    scene_.replace(at, std::move(changed));
    return std::nullopt;
  }

  // Whether `parent` may hold `id`: it exists, is not `id` nor under it, and
  // the chain above stays within the depth limit.
  Check parent_problem(const std::string& id, const std::string& parent) const {
    if (parent.empty()) return std::nullopt;
    Instances::iterator above;
    if (auto wrong = existing("parent", parent, above)) return wrong;
    std::size_t depth = 1;
    for (std::string at = parent; !at.empty(); at = scene_.instances_.at(at).parent, ++depth) {
      if (at == id)
        return Wrong{"parent", "'" + parent + "' is '" + id + "' or under it: an instance cannot hold itself"};
      if (depth > scene_.limits_.max_depth) {
        return Wrong{"parent", "would put '" + id + "' more than " + std::to_string(scene_.limits_.max_depth) +
                                   " instances deep"};
      }
    }
    return std::nullopt;
  }

  Check create(const session::CreateInstance& c) {
    if (auto wrong = id_problem("instance", c.instance())) return wrong;
    if (scene_.instances_.count(c.instance()) != 0) {
      return Wrong{"instance", "'" + c.instance() + "' exists already"};
    }
    if (scene_.instances_.size() >= scene_.limits_.max_instances) {
      return Wrong{"instance",
                   "the scene holds " + std::to_string(scene_.limits_.max_instances) + " instances, the most it may"};
    }
    if (auto wrong = id_problem("asset", c.asset())) return wrong;
    if (scene_.is_loading(c.asset())) {
      return Wrong{"asset", "'" + c.asset() + "' is still loading (its LoadAsset has not been answered)"};
    }
    if (!scene_.has_asset(c.asset())) return Wrong{"asset", "no asset '" + c.asset() + "' is loaded"};
    if (auto wrong = parent_problem(c.instance(), c.parent())) return wrong;
    Instance instance;
    instance.asset = c.asset();
    instance.parent = c.parent();
    instance.visible = !c.hidden();
    if (scene_.animated_.contains(c.asset())) instance.animation = AnimationClock{true, 0.0, frame_};
    if (auto wrong = read_transform(c.transform(), instance.pose)) return wrong;
    put(c.instance(), std::move(instance));
    return std::nullopt;
  }

  Check transform(const session::SetTransform& t) {
    return modify(t.instance(), [&](Instance& changed) { return read_transform(t.transform(), changed.pose); });
  }

  Check parent(const session::SetParent& p) {
    return modify(p.instance(), [&](Instance& changed) -> Check {
      if (auto wrong = parent_problem(p.instance(), p.parent())) return wrong;
      // The instances under it go along: each must stay within the depth limit.
      if (auto wrong = subtree_depth_problem(p.instance(), p.parent())) return wrong;
      changed.parent = p.parent();
      return std::nullopt;
    });
  }

  Check visible(const session::SetVisible& v) {
    return modify(v.instance(), [&](Instance& changed) -> Check {
      changed.visible = v.visible();
      return std::nullopt;
    });
  }

  Check remove(const session::RemoveInstance& r) {
    Instances::iterator instance;
    if (auto wrong = existing("instance", r.instance(), instance)) return wrong;
    // The instances under it first, deepest first, then itself.
    std::vector<std::string> order{r.instance()};
    for (std::size_t i = 0; i < order.size(); ++i) {
      for (const std::string& child : scene_.children(order[i])) order.push_back(child);
    }
    for (auto it = order.rbegin(); it != order.rend(); ++it) put(*it, std::nullopt);
    return std::nullopt;
  }

  Check factors(const session::SetFactors& f) {
    return modify(f.instance(), [&](Instance& changed) -> Check {
      if (!f.base_color().empty()) {
        if (auto wrong = count_problem("base_color", f.base_color_size(), {4}, "[r, g, b, a]")) return wrong;
        if (auto wrong = numbers_problem("base_color", f.base_color(), 0.0, 1.0)) return wrong;
        changed.base_color = {f.base_color(0), f.base_color(1), f.base_color(2), f.base_color(3)};
      }
      if (!f.emissive().empty()) {
        if (auto wrong = count_problem("emissive", f.emissive_size(), {3}, "[r, g, b]")) return wrong;
        if (auto wrong = numbers_problem("emissive", f.emissive(), 0.0, scene::kMaxEmissiveFactor)) return wrong;
        changed.emissive = {f.emissive(0), f.emissive(1), f.emissive(2)};
      }
      return std::nullopt;
    });
  }

  Check navigation(const session::SetNavigation& n) {
    scene::Pose pose = scene_.navigation_.pose;
    if (auto wrong = read_transform(n.transform(), pose)) return wrong;
    if (pose.scale.x != pose.scale.y || pose.scale.x != pose.scale.z) {
      return Wrong{"transform.scale", "must be the same on every axis: give [s]"};
    }
    if (!navigation_before_) navigation_before_ = scene_.navigation_;
    scene_.navigation_ = {pose, scene_.navigation_.sets + 1};
    return std::nullopt;
  }

  Check light(const session::SwitchLight& l) {
    if (l.light() >= scene_.light_count_ && !scene_.point_lights_.contains(l.light())) {
      return Wrong{"light", (scene_.light_count_ == 0
                                 ? std::string("the scene has no point lights")
                                 : "the scene's point lights are 0 to " + std::to_string(scene_.light_count_ - 1)) +
                                ", and no light " + std::to_string(l.light()) + " was added"};
    }
    switches()[l.light()] = l.on();
    return std::nullopt;
  }

  // Adds a light after the scene's, or changes one added before.
  Check point_light(const session::SetPointLight& l) {
    const std::size_t first = scene_.light_count_;
    const std::size_t most = scene_.limits_.max_point_lights;
    if (l.light() < first || l.light() - first >= most) {
      return Wrong{"light", "lights added take the indices " + std::to_string(first) + " to " +
                                std::to_string(first + most - 1) + ", after the scene's own (got " +
                                std::to_string(l.light()) + ")"};
    }
    const auto there = scene_.point_lights_.find(l.light());
    if (there == scene_.point_lights_.end()) {
      if (l.position().empty()) return Wrong{"position", "is needed to add a light"};
      if (scene_.point_lights_.size() >= most) {
        return Wrong{"light", "the scene has " + std::to_string(most) + " lights added, the most it may"};
      }
    }
    scene::PointLightState light = there == scene_.point_lights_.end() ? scene::PointLightState{} : there->second;
    if (!l.position().empty()) {
      if (auto wrong = count_problem("position", l.position_size(), {3}, "[x, y, z]")) return wrong;
      if (auto wrong = numbers_problem("position", l.position(), -kMaxPosition, kMaxPosition)) return wrong;
      light.position = {l.position(0), l.position(1), l.position(2)};
    }
    if (!l.colour().empty()) {
      if (auto wrong = count_problem("colour", l.colour_size(), {3}, "[r, g, b]")) return wrong;
      if (auto wrong = numbers_problem("colour", l.colour(), 0.0, scene::kMaxLightColour)) return wrong;
      light.colour = {l.colour(0), l.colour(1), l.colour(2)};
    }
    if (l.has_intensity()) {
      if (!std::isfinite(l.intensity()) || l.intensity() < 0.0 || l.intensity() > scene::kMaxLightIntensity) {
        return Wrong{"intensity", "must be in [0, " + number_text(scene::kMaxLightIntensity) + "] (got " +
                                      number_text(l.intensity()) + ")"};
      }
      light.intensity = l.intensity();
    }
    added_lights()[l.light()] = light;
    return std::nullopt;
  }

  // A light added goes, and its switch with it.
  Check remove_point_light(const session::RemovePointLight& r) {
    if (!scene_.point_lights_.contains(r.light())) {
      return Wrong{"light", "no light " + std::to_string(r.light()) + " was added"};
    }
    added_lights().erase(r.light());
    if (scene_.light_switches_.contains(r.light())) switches().erase(r.light());
    return std::nullopt;
  }

  // The light switches and the lights added, to change: kept as they were
  // first, for undo().
  std::map<std::uint32_t, bool>& switches() {
    if (!lights_before_) lights_before_ = scene_.light_switches_;
    return scene_.light_switches_;
  }
  std::map<std::uint32_t, scene::PointLightState>& added_lights() {
    if (!point_lights_before_) point_lights_before_ = scene_.point_lights_;
    return scene_.point_lights_;
  }

  // The clock starts here from where the scene's time has the animations in
  // this frame, or from where its own clock has them.
  Check animation(const session::SetAnimation& a) {
    return modify(a.instance(), [&](Instance& changed) -> Check {
      if (!a.has_playing() && !a.has_seek()) return Wrong{"", "give playing, seek or both"};
      const double period = scene_.frame_period_;
      AnimationClock clock;
      clock.anchor = frame_;
      clock.position = changed.animation ? changed.animation->at(frame_, period) : static_cast<double>(frame_) * period;
      clock.playing = changed.animation ? changed.animation->playing : true;
      if (a.has_seek()) {
        if (!std::isfinite(a.seek()) || a.seek() < 0.0 || a.seek() > kMaxSeek) {
          return Wrong{"seek",
                       "must be in [0, " + number_text(kMaxSeek) + "] seconds (got " + number_text(a.seek()) + ")"};
        }
        clock.position = a.seek();
      }
      if (a.has_playing()) clock.playing = a.playing();
      changed.animation = clock;
      return std::nullopt;
    });
  }

  // The depth of `id`'s deepest descendant, below `parent`.
  Check subtree_depth_problem(const std::string& id, const std::string& parent) const {
    std::size_t above = 1;  // `id` itself
    for (std::string at = parent; !at.empty(); at = scene_.instances_.at(at).parent) ++above;
    std::vector<std::pair<std::string, std::size_t>> stack{{id, above}};
    while (!stack.empty()) {
      auto [at, depth] = stack.back();
      stack.pop_back();
      if (depth > scene_.limits_.max_depth + 1) {
        return Wrong{"parent", "would put '" + at + "' more than " + std::to_string(scene_.limits_.max_depth) +
                                   " instances deep"};
      }
      for (const std::string& child : scene_.children(at)) stack.emplace_back(child, depth + 1);
    }
    return std::nullopt;
  }

  LiveScene& scene_;
  std::uint64_t frame_;
  std::set<std::string> touched_;
  std::vector<std::pair<std::string, std::optional<Instance>>> before_;
  std::optional<NavigationSet> navigation_before_;
  std::optional<std::map<std::uint32_t, bool>> lights_before_;
  std::optional<std::map<std::uint32_t, scene::PointLightState>> point_lights_before_;
};

double AnimationClock::at(std::uint64_t frame, double period) const {
  if (!playing || frame <= anchor) return position;
  return std::min(position + static_cast<double>(frame - anchor) * period, scene::kMaxAnimationSeconds);
}

void LiveScene::begin_run(std::uint64_t last) {
  for (auto& [id, instance] : instances_) {
    if (!instance.animation) continue;
    instance.animation = AnimationClock{instance.animation->playing, instance.animation->at(last, frame_period_), 0};
    edited_.insert(id);
  }
  edits_this_frame_ = 0;
}

LiveScene LiveScene::of(const scene::SceneDefinition& scene, LiveSceneLimits limits, double frame_rate) {
  // The scene's own clock's period, so that a clock set where the scene's time is starts there exactly.
  LiveScene live(limits, static_cast<double>(clock::frame_period(frame_rate)) / clock::kNanosPerSecond);
  live.add_asset(scene.asset_id);
  live.set_light_count(scene.lights.size());
  return live;
}

const std::set<std::string>& LiveScene::children(const std::string& parent) const {
  static const std::set<std::string> kNone;
  const auto found = children_.find(parent);
  return found == children_.end() ? kNone : found->second;
}

namespace {
bool plays(const Instance* instance) {
  return instance != nullptr && instance->animation && instance->animation->playing;
}
}  // namespace

void LiveScene::note_edit(const std::string& id, bool was_playing, const Instance* now) {
  edited_.insert(id);
  if (plays(now)) {
    playing_.insert(id);
  } else if (was_playing) {
    playing_.erase(id);
  }
}

void LiveScene::replace(Instances::iterator at, Instance instance) {
  assert(at->second.parent == instance.parent);
  note_edit(at->first, plays(&at->second), &instance);
  at->second = std::move(instance);
}

void LiveScene::put(const std::string& id, std::optional<Instance> instance) {
  const auto old = instances_.find(id);
  if (instance && old != instances_.end() && old->second.parent == instance->parent) {
    replace(old, std::move(*instance));  // where it was, under the same parent: no index changes
    return;
  }
  note_edit(id, old != instances_.end() && plays(&old->second), instance ? &*instance : nullptr);
  if (old != instances_.end()) {
    auto& siblings = children_[old->second.parent];
    siblings.erase(id);
    if (siblings.empty()) children_.erase(old->second.parent);
    instances_.erase(old);
  }
  if (instance) {
    children_[instance->parent].insert(id);
    instances_.emplace(id, std::move(*instance));
  }
}

std::optional<Refusal> LiveScene::apply(const session::Transaction& transaction, std::uint64_t frame) {
  const auto count = static_cast<std::size_t>(transaction.edits_size());
  if (count > limits_.max_edits_per_frame - edits_this_frame_) {
    return Refusal{0, "edits",
                   std::to_string(count) + " edits, but " +
                       std::to_string(limits_.max_edits_per_frame - edits_this_frame_) + " of this frame's " +
                       std::to_string(limits_.max_edits_per_frame) + " are left: send the rest in a later frame"};
  }
  Edits edits(*this, frame);
  for (std::size_t i = 0; i < count; ++i) {
    if (auto wrong = edits.apply(transaction.edits(static_cast<int>(i)))) {
      edits.undo();
      const std::string at = "edits[" + std::to_string(i) + "]";
      return Refusal{i, wrong->field.empty() ? at : at + "." + wrong->field, std::move(wrong->reason)};
    }
  }
  edits_this_frame_ += count;
  return std::nullopt;
}

session::SceneContents scene_contents(const LiveScene& live, std::uint64_t frame) {
  session::SceneContents contents;
  contents.set_frame(frame);
  for (const std::string& asset : live.assets()) contents.add_assets(asset);
  for (const auto& [id, instance] : live.instances()) {
    session::InstanceView& view = *contents.add_instances();
    view.set_instance(id);
    view.set_asset(instance.asset);
    view.set_parent(instance.parent);
    view.set_hidden(!instance.visible);
    to_transform(instance.pose, *view.mutable_transform());
    for (int i = 0; i < 4; ++i) view.add_base_color(instance.base_color[i]);
    for (int i = 0; i < 3; ++i) view.add_emissive(instance.emissive[i]);
    if (instance.animation) {
      view.mutable_animation()->set_playing(instance.animation->playing);
      view.mutable_animation()->set_position(instance.animation->at(frame, live.frame_period()));
    }
  }
  to_transform(live.navigation().pose, *contents.mutable_navigation());
  contents.set_light_count(static_cast<std::uint32_t>(live.light_count()));
  for (const auto& [light, on] : live.light_switches()) {
    session::SwitchLight& l = *contents.add_lights();
    l.set_light(light);
    l.set_on(on);
  }
  for (const auto& [index, light] : live.point_lights()) {
    session::SetPointLight& l = *contents.add_point_lights();
    l.set_light(index);
    for (int i = 0; i < 3; ++i) l.add_position(light.position[i]);
    for (int i = 0; i < 3; ++i) l.add_colour(light.colour[i]);
    l.set_intensity(light.intensity);
  }
  contents.set_max_point_lights(static_cast<std::uint32_t>(live.max_point_lights()));
  return contents;
}

LiveSceneLimits live_scene_limits(const std::optional<config::ApiServer>& api) {
  LiveSceneLimits limits;
  if (api) {
    limits.max_instances = api->max_instances;
    limits.max_edits_per_frame = api->max_edits_per_frame;
  }
  return limits;
}

scene::InstanceState instance_state(const LiveScene& live, const Instance& instance, std::uint64_t frame) {
  scene::InstanceState placed;
  placed.asset = instance.asset;
  placed.parent = instance.parent;
  placed.pose = {instance.pose, instance.pose};
  placed.visible = instance.visible;
  placed.base_color = instance.base_color;
  placed.emissive = instance.emissive;
  if (instance.animation) {
    placed.animation = scene::AnimationTimes{instance.animation->at(frame, live.frame_period()),
                                             instance.animation->at(frame + 1, live.frame_period())};
  }
  return placed;
}

void put_live(const LiveScene& live, std::uint64_t frame, scene::SceneState& state) {
  state.instances.clear();
  for (const auto& [id, instance] : live.instances()) {
    // In order: each goes at the end, found without a search.
    state.instances.emplace_hint(state.instances.end(), id, instance_state(live, instance, frame));
  }
  put_live_lights(live, state);
}

void put_live_lights(const LiveScene& live, scene::SceneState& state) {
  for (const auto& [light, on] : live.light_switches()) {
    if (on) {
      state.lights_off.erase(light);
    } else {
      state.lights_off.insert(light);
    }
  }
  state.navigation = {live.navigation().pose, live.navigation().pose};
  state.point_lights = live.point_lights();
}

}  // namespace optique::master
