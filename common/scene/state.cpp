#include "scene/state.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <glm/common.hpp>
#include <string>
#include <string_view>

#include "util/id_text.h"

namespace optique::scene {
namespace {

// A hash of 64-bit words: each word multiplied in, turned and multiplied
// again (the round of the xxHash family), a final mix so that every bit of the
// input reaches every bit of the value. Byte-at-a-time FNV-1a took 13 % of a
// node's frame with 1,000 instances moving: eight multiplications a word
// against two.
class StateHasher {
 public:
  void add(std::uint64_t v) {
    hash_ += v * kMultiplyIn;
    hash_ = std::rotl(hash_, 31) * kTurnedBy;
  }
  void add(double v) { add(std::bit_cast<std::uint64_t>(v)); }
  void add(const glm::dvec3& v) {
    add(v.x);
    add(v.y);
    add(v.z);
  }
  void add(const glm::dquat& q) {
    add(q.w);
    add(q.x);
    add(q.y);
    add(q.z);
  }
  void add(const Pose& p) {
    add(p.position);
    add(p.rotation);
    add(p.scale);
  }
  void add(const glm::dvec4& v) {
    add(glm::dvec3(v));
    add(v.w);
  }
  void add(std::string_view text) {
    add(static_cast<std::uint64_t>(text.size()));
    // Eight bytes a word, the first lowest: the same words on a machine of
    // either byte order.
    std::uint64_t word = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
      word |= static_cast<std::uint64_t>(static_cast<unsigned char>(text[i])) << (8 * (i % 8));
      if (i % 8 == 7) {
        add(word);
        word = 0;
      }
    }
    if (text.size() % 8 != 0) add(word);
  }
  void add(const InstanceState& i) {
    add(i.asset);
    add(i.parent);
    add(i.pose.now);
    add(i.pose.next);
    add(static_cast<std::uint64_t>(i.visible ? 1 : 0));
    add(i.base_color);
    add(i.emissive);
    add(static_cast<std::uint64_t>(i.animation ? 1 : 0));
    if (i.animation) {
      add(i.animation->now);
      add(i.animation->next);
    }
  }
  void add(const PointLightState& light) {
    add(light.position);
    add(light.colour);
    add(light.intensity);
  }
  [[nodiscard]] std::uint64_t value() const {
    std::uint64_t v = hash_;
    v ^= v >> 33;
    v *= kMultiplyIn;
    v ^= v >> 29;
    v *= kMix;
    v ^= v >> 32;
    return v;
  }

 private:
  // Odd 64-bit constants with well-spread bits (those of xxHash64).
  static constexpr std::uint64_t kMultiplyIn = 0xC2B2AE3D27D4EB4Full;
  static constexpr std::uint64_t kTurnedBy = 0x9E3779B185EBCA87ull;
  static constexpr std::uint64_t kMix = 0x165667B19E3779F9ull;
  std::uint64_t hash_ = 0x27D4EB2F165667C5ull;
};

// Equality as the hash sees it: bit for bit (0.0 and -0.0 differ), so a change
// the hash notices is never left out of a delta.
bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

bool identical(const glm::dvec3& a, const glm::dvec3& b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

bool identical(const glm::dquat& a, const glm::dquat& b) {
  return same_bits(a.w, b.w) && same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

bool identical(const Pose& a, const Pose& b) {
  return identical(a.position, b.position) && identical(a.rotation, b.rotation) && identical(a.scale, b.scale);
}

bool identical(const ObjectState& a, const ObjectState& b) {
  return identical(a.now, b.now) && identical(a.next, b.next);
}

// Every field but the pose.
bool identical_but_pose(const InstanceState& a, const InstanceState& b) {
  return a.asset == b.asset && a.parent == b.parent && a.visible == b.visible &&
         identical(glm::dvec3(a.base_color), glm::dvec3(b.base_color)) && same_bits(a.base_color.w, b.base_color.w) &&
         identical(a.emissive, b.emissive) && a.animation.has_value() == b.animation.has_value() &&
         (!a.animation ||
          (same_bits(a.animation->now, b.animation->now) && same_bits(a.animation->next, b.animation->next)));
}

void to_wire(const glm::dvec3& v, wire::Vec3& out) {
  out.set_x(v.x);
  out.set_y(v.y);
  out.set_z(v.z);
}

void to_wire(const glm::dquat& q, wire::Quat& out) {
  out.set_w(q.w);
  out.set_x(q.x);
  out.set_y(q.y);
  out.set_z(q.z);
}

void to_wire(const Pose& p, wire::Pose& out) {
  to_wire(p.position, *out.mutable_position());
  to_wire(p.rotation, *out.mutable_rotation());
  to_wire(p.scale, *out.mutable_scale());
}

// An instance's pose packed: position, rotation (w first), scale.
constexpr int kPackedPose = 10;

void to_wire(std::uint32_t id, const ObjectState& o, wire::ObjectState& out) {
  out.set_id(id);
  to_wire(o.now, *out.mutable_now());
  to_wire(o.next, *out.mutable_next());
}

// An instance's two poses packed: once when they are the same.
void pose_to_wire(const ObjectState& poses, google::protobuf::RepeatedField<double>& pose) {
  const bool still = identical(poses.now, poses.next);
  pose.Reserve(still ? kPackedPose : 2 * kPackedPose);
  for (const Pose* p : {&poses.now, &poses.next}) {
    for (double v : {p->position.x, p->position.y, p->position.z, p->rotation.w, p->rotation.x, p->rotation.y,
                     p->rotation.z, p->scale.x, p->scale.y, p->scale.z}) {
      pose.AddAlreadyReserved(v);
    }
    if (still) break;
  }
}

void to_wire(const std::string& id, const InstanceState& i, wire::InstanceState& out) {
  out.set_id(id);
  out.set_asset(i.asset);
  out.set_parent(i.parent);
  pose_to_wire(i.pose, *out.mutable_pose());
  out.set_hidden(!i.visible);
  // The factors that change nothing are left out.
  if (i.base_color != glm::dvec4(1.0)) {
    for (int k = 0; k < 4; ++k) out.add_base_color(i.base_color[k]);
  }
  if (i.emissive != glm::dvec3(1.0)) {
    for (int k = 0; k < 3; ++k) out.add_emissive(i.emissive[k]);
  }
  if (i.animation) {
    out.mutable_animation()->set_now(i.animation->now);
    out.mutable_animation()->set_next(i.animation->next);
  }
}

const glm::dquat kNoTurn{1.0, 0.0, 0.0, 0.0};
const ObjectState kUnmoved{};

void to_wire(const SceneState& s, wire::ViewerState& out) {
  to_wire(s.eye_now, *out.mutable_eye_now());
  to_wire(s.eye_next, *out.mutable_eye_next());
  // Only a turned head is written: an untracked viewer's state stays as it was.
  if (!identical(s.head_now, kNoTurn) || !identical(s.head_next, kNoTurn)) {
    to_wire(s.head_now, *out.mutable_head_now());
    to_wire(s.head_next, *out.mutable_head_next());
  }
  // The same for the navigation: a viewer who does not travel writes none.
  if (!identical(s.navigation, kUnmoved)) {
    to_wire(s.navigation.now, *out.mutable_navigation_now());
    to_wire(s.navigation.next, *out.mutable_navigation_next());
  }
}

bool identical(const PointLightState& a, const PointLightState& b) {
  return identical(a.position, b.position) && identical(a.colour, b.colour) && same_bits(a.intensity, b.intensity);
}

// Where a value read from the wire is ("instance a (now) position"), for an
// error message: its parts are put together only when there is an error.
// Reading a frame's change must not build a dozen strings per instance that
// nobody reads (a tenth of a node's time with 1,000 instances moving).
struct Where {
  std::string_view part;
  const Where* outer = nullptr;
  [[nodiscard]] std::string text() const { return outer != nullptr ? outer->text().append(part) : std::string(part); }
  [[nodiscard]] Where operator/(std::string_view inner) const { return {inner, this}; }
};

// Reading from the wire checks every number: NaN or Inf never reaches a matrix.
Result<glm::dvec3> checked(const glm::dvec3& v, const Where& what) {
  if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
    return Error{what.text() + " has a non-finite coordinate"};
  }
  return v;
}

Result<glm::dquat> checked(const glm::dquat& rotation, const Where& what) {
  const double norm =
      std::sqrt(rotation.w * rotation.w + rotation.x * rotation.x + rotation.y * rotation.y + rotation.z * rotation.z);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6) {
    return Error{what.text() + " is not a unit quaternion (norm " + std::to_string(norm) + ")"};
  }
  return rotation;
}

Result<glm::dvec3> from_wire(const wire::Vec3& v, const Where& what) {
  return checked(glm::dvec3(v.x(), v.y(), v.z()), what);
}

Result<glm::dquat> from_wire(const wire::Quat& q, const Where& what) {
  return checked(glm::dquat(q.w(), q.x(), q.y(), q.z()), what);
}

// A packed pose (kPackedPose numbers from `v`), checked as a Pose message is.
Result<Pose> packed_from_wire(const double* v, const Where& what) {
  const Pose pose{{v[0], v[1], v[2]}, glm::dquat(v[3], v[4], v[5], v[6]), {v[7], v[8], v[9]}};
  if (auto ok = checked(pose.position, what / " position"); !ok) return Error{ok.error()};
  if (auto ok = checked(pose.rotation, what / " rotation"); !ok) return Error{ok.error()};
  if (auto ok = checked(pose.scale, what / " scale"); !ok) return Error{ok.error()};
  return pose;
}

Result<Pose> from_wire(const wire::Pose& p, const Where& what) {
  Pose pose;
  auto position = from_wire(p.position(), what / " position");
  if (!position) return Error{position.error()};
  pose.position = position.value();
  // A missing scale means unit scale; a missing rotation means identity.
  if (p.has_scale()) {
    auto scale = from_wire(p.scale(), what / " scale");
    if (!scale) return Error{scale.error()};
    pose.scale = scale.value();
  }
  if (p.has_rotation()) {
    auto rotation = from_wire(p.rotation(), what / " rotation");
    if (!rotation) return Error{rotation.error()};
    pose.rotation = rotation.value();
  }
  return pose;
}

Result<ObjectState> from_wire(const wire::ObjectState& o) {
  const std::string id = std::to_string(o.id());
  const Where object{"object "};
  const Where what = object / id;
  auto now = from_wire(o.now(), what / " (now)");
  if (!now) return Error{now.error()};
  auto next = from_wire(o.next(), what / " (next)");
  if (!next) return Error{next.error()};
  return ObjectState{now.value(), next.value()};
}

// Numbers in [low, high], `count` of them or none.
Result<void> factors_from_wire(const google::protobuf::RepeatedField<double>& v, int count, double high,
                               const Where& what) {
  if (!v.empty() && v.size() != count) {
    return Error{what.text() + " has " + std::to_string(v.size()) + " numbers, not " + std::to_string(count)};
  }
  for (double x : v) {
    if (!std::isfinite(x) || x < 0.0 || x > high) {
      return Error{what.text() + " is outside [0, " + std::to_string(high) + "]"};
    }
  }
  return {};
}

// An instance's packed poses: kPackedPose numbers, or twice that when the next differs.
Result<ObjectState> poses_from_wire(const google::protobuf::RepeatedField<double>& v, const Where& what) {
  if (v.size() != kPackedPose && v.size() != 2 * kPackedPose) {
    return Error{what.text() + "'s pose has " + std::to_string(v.size()) + " numbers, not " +
                 std::to_string(kPackedPose) + " or " + std::to_string(2 * kPackedPose)};
  }
  auto now = packed_from_wire(v.data(), what / " (now)");
  if (!now) return Error{now.error()};
  if (v.size() == kPackedPose) return ObjectState{now.value(), now.value()};
  auto next = packed_from_wire(v.data() + kPackedPose, what / " (next)");
  if (!next) return Error{next.error()};
  return ObjectState{now.value(), next.value()};
}

Result<std::pair<std::string, InstanceState>> from_wire(const wire::InstanceState& i) {
  if (!is_instance_id(i.id())) return Error{"an instance's id is not one (1 to 64 of a-z A-Z 0-9 - _ .)"};
  const Where instance{"instance "};
  const Where what = instance / i.id();
  if (!is_instance_id(i.asset())) return Error{what.text() + ": its asset's id is not one"};
  if (!i.parent().empty() && !is_instance_id(i.parent())) return Error{what.text() + ": its parent's id is not one"};
  if (i.parent() == i.id()) return Error{what.text() + " is its own parent"};
  InstanceState out;
  out.asset = i.asset();
  out.parent = i.parent();
  out.visible = !i.hidden();
  auto pose = poses_from_wire(i.pose(), what);
  if (!pose) return Error{pose.error()};
  out.pose = pose.value();
  if (auto ok = factors_from_wire(i.base_color(), 4, 1.0, what / " base colour"); !ok) return Error{ok.error()};
  if (auto ok = factors_from_wire(i.emissive(), 3, kMaxEmissiveFactor, what / " emissive"); !ok) {
    return Error{ok.error()};
  }
  if (!i.base_color().empty()) out.base_color = {i.base_color(0), i.base_color(1), i.base_color(2), i.base_color(3)};
  if (!i.emissive().empty()) out.emissive = {i.emissive(0), i.emissive(1), i.emissive(2)};
  if (i.has_animation()) {
    for (double t : {i.animation().now(), i.animation().next()}) {
      if (!std::isfinite(t) || t < 0.0 || t > kMaxAnimationSeconds) {
        return Error{what.text() + ": its animation's time is outside [0, " + std::to_string(kMaxAnimationSeconds) +
                     "] s"};
      }
    }
    out.animation = AnimationTimes{i.animation().now(), i.animation().next()};
  }
  return std::pair{i.id(), std::move(out)};
}

void to_wire(std::uint32_t index, const PointLightState& light, wire::PointLightState& out) {
  out.set_light(index);
  for (int k = 0; k < 3; ++k) {
    out.add_position(light.position[k]);
    out.add_colour(light.colour[k]);
  }
  out.set_intensity(light.intensity);
}

Result<std::pair<std::uint32_t, PointLightState>> from_wire(const wire::PointLightState& l) {
  const std::string name = "point light " + std::to_string(l.light());
  if (l.light() >= kMaxLightIndex) return Error{name + ": the index is " + std::to_string(kMaxLightIndex) + " or more"};
  if (l.position_size() != 3)
    return Error{name + ": its position has " + std::to_string(l.position_size()) + " numbers, not 3"};
  if (l.colour_size() != 3)
    return Error{name + ": its colour has " + std::to_string(l.colour_size()) + " numbers, not 3"};
  PointLightState light{
      {l.position(0), l.position(1), l.position(2)}, {l.colour(0), l.colour(1), l.colour(2)}, l.intensity()};
  for (int k = 0; k < 3; ++k) {
    if (!(std::abs(light.position[k]) <= kMaxLightDistance)) return Error{name + "'s position is not within ±1e6 m"};
    if (!(light.colour[k] >= 0.0 && light.colour[k] <= kMaxLightColour)) {
      return Error{name + "'s colour is outside [0, " + std::to_string(kMaxLightColour) + "]"};
    }
  }
  if (!(light.intensity >= 0.0 && light.intensity <= kMaxLightIntensity)) {
    return Error{name + "'s intensity is outside [0, " + std::to_string(kMaxLightIntensity) + "]"};
  }
  return std::pair{l.light(), light};
}

// Every instance a change names, and every one left without its parent by a
// removal: its parent is there, and the chain above it ends at the world
// within kMaxInstanceDepth (so without a cycle). Each is given with its state
// as the delta would leave it, and `lookup` gives any other instance so: an
// instance under the world costs no search (moving a thousand instances, their
// searches were a tenth of a node's time).
using Named = std::pair<const std::string*, const InstanceState*>;
template <class Lookup>
Result<void> check_parents(const std::vector<Named>& named, const Lookup& lookup) {
  for (const auto& [id_of, instance] : named) {
    const std::string& id = *id_of;
    std::size_t depth = 0;
    for (const InstanceState* at = instance; !at->parent.empty(); ++depth) {
      if (depth == kMaxInstanceDepth) {
        return Error{"instance " + id + " is more than " + std::to_string(kMaxInstanceDepth) +
                     " instances deep, or under itself"};
      }
      const InstanceState* parent = lookup(at->parent);
      if (parent == nullptr) return Error{"instance " + id + " is under " + at->parent + ", which does not exist"};
      at = parent;
    }
  }
  return {};
}

using Instances = std::map<std::string, InstanceState>;

// The instances a delta moves, each found in the state with its new poses, or
// what is wrong: an id that is not one, an instance not there, changed or
// removed by the delta too, or moved twice, a pose that is not one. Nothing
// is changed. The master names them in id order: each is looked for next to
// the one before first (a frame that moves them all costs no search).
template <class Changed>
Result<std::vector<std::pair<Instances::iterator, ObjectState>>> moves_from_wire(const wire::StateDelta& delta,
                                                                                 Instances& instances,
                                                                                 const Changed& changed_instance,
                                                                                 const std::set<std::string>& removed) {
  std::vector<std::pair<Instances::iterator, ObjectState>> moves;
  if (delta.instances_moved().empty()) return moves;
  moves.reserve(static_cast<std::size_t>(delta.instances_moved_size()));
  bool ascending = true;
  auto at = instances.begin();
  for (const wire::InstanceMove& m : delta.instances_moved()) {
    const std::string& id = m.id();
    if (!is_instance_id(id)) return Error{"delta moves an instance whose id is not one"};
    ascending = ascending && (moves.empty() || moves.back().first->first < id);
    if (at == instances.end() || at->first != id) {
      const auto next = at == instances.end() ? at : std::next(at);
      at = next != instances.end() && next->first == id ? next : instances.find(id);
    }
    if (at == instances.end() || removed.contains(id) || changed_instance(id) != nullptr) {
      return Error{"delta moves instance " + id + ", which it cannot: it is not there, or changed or removed too"};
    }
    const Where instance{"instance "};
    auto pose = poses_from_wire(m.pose(), instance / id);
    if (!pose) return Error{"delta: " + pose.error()};
    moves.emplace_back(at, pose.value());
  }
  if (!ascending) {  // a peer's own order: each once
    std::vector<const std::string*> ids;
    for (const auto& move : moves) ids.push_back(&move.first->first);
    std::sort(ids.begin(), ids.end(), [](const auto* a, const auto* b) { return *a < *b; });
    const auto twice =
        std::adjacent_find(ids.begin(), ids.end(), [](const auto* a, const auto* b) { return *a == *b; });
    if (twice != ids.end()) return Error{"delta moves instance " + **twice + " twice"};
  }
  return moves;
}

struct ViewerPair {
  glm::dvec3 eye_now;
  glm::dvec3 eye_next;
  glm::dquat head_now{kNoTurn};
  glm::dquat head_next{kNoTurn};
  ObjectState navigation;
};

// A navigation pose: finite, turned by a unit quaternion, scaled alike on
// every axis within the bounds.
Result<Pose> navigation_from_wire(const wire::Pose& p, const Where& what) {
  auto pose = from_wire(p, what);
  if (!pose) return pose;
  const glm::dvec3& s = pose.value().scale;
  if (s.x != s.y || s.x != s.z || !(s.x >= kLeastNavigationScale && s.x <= kMostNavigationScale)) {
    return Error{what.text() + " scale must be the same on every axis and in [1e-4, 1e4]"};
  }
  return pose;
}

Result<ViewerPair> viewer_from_wire(const wire::ViewerState& v) {
  ViewerPair out;
  auto now = from_wire(v.eye_now(), Where{"viewer eye (now)"});
  if (!now) return Error{now.error()};
  out.eye_now = now.value();
  auto next = from_wire(v.eye_next(), Where{"viewer eye (next)"});
  if (!next) return Error{next.error()};
  out.eye_next = next.value();
  if (v.has_head_now() != v.has_head_next()) return Error{"viewer head: give its turn now and next, or neither"};
  if (v.has_head_now()) {
    auto head_now = from_wire(v.head_now(), Where{"viewer head (now)"});
    if (!head_now) return Error{head_now.error()};
    out.head_now = head_now.value();
    auto head_next = from_wire(v.head_next(), Where{"viewer head (next)"});
    if (!head_next) return Error{head_next.error()};
    out.head_next = head_next.value();
  }
  if (v.has_navigation_now() != v.has_navigation_next()) {
    return Error{"viewer navigation: give it now and next, or neither"};
  }
  if (v.has_navigation_now()) {
    auto now_pose = navigation_from_wire(v.navigation_now(), Where{"viewer navigation (now)"});
    if (!now_pose) return Error{now_pose.error()};
    auto next_pose = navigation_from_wire(v.navigation_next(), Where{"viewer navigation (next)"});
    if (!next_pose) return Error{next_pose.error()};
    out.navigation = {now_pose.value(), next_pose.value()};
  }
  return out;
}

void set_viewer(SceneState& state, const ViewerPair& viewer) {
  state.eye_now = viewer.eye_now;
  state.eye_next = viewer.eye_next;
  state.head_now = viewer.head_now;
  state.head_next = viewer.head_next;
  state.navigation = viewer.navigation;
}

}  // namespace

bool is_instance_id(std::string_view id) {
  if (id.empty() || id.size() > kMaxInstanceIdLength) return false;
  return std::all_of(id.begin(), id.end(), util::is_id_char);
}

// A viewer that does not move is where it is, to the bit.
glm::dvec3 eyes_at(const SceneState& state, double fraction) {
  return identical(state.eye_now, state.eye_next) ? state.eye_now : glm::mix(state.eye_now, state.eye_next, fraction);
}

glm::dquat head_at(const SceneState& state, double fraction) {
  return identical(state.head_now, state.head_next) ? state.head_now
                                                    : glm::slerp(state.head_now, state.head_next, fraction);
}

std::uint64_t instance_hash(const std::string& id, const InstanceState& instance) {
  StateHasher h;
  h.add(std::string_view(id));
  h.add(instance);
  return h.value();
}

InstancesHash instances_hash(const SceneState& state) {
  InstancesHash instances;
  for (const auto& [id, instance] : state.instances) instances.sum += instance_hash(id, instance);
  return instances;
}

std::uint64_t state_hash(const SceneState& state) { return state_hash(state, instances_hash(state)); }

std::uint64_t state_hash(const SceneState& state, InstancesHash instances) {
  StateHasher h;
  h.add(static_cast<std::uint64_t>(state.objects.size()));
  for (const auto& [id, object] : state.objects) {
    h.add(static_cast<std::uint64_t>(id));
    h.add(object.now);
    h.add(object.next);
  }
  h.add(state.eye_now);
  h.add(state.eye_next);
  h.add(state.head_now);
  h.add(state.head_next);
  h.add(state.navigation.now);
  h.add(state.navigation.next);
  h.add(static_cast<std::uint64_t>(state.lights_off.size()));
  for (std::uint32_t light : state.lights_off) h.add(static_cast<std::uint64_t>(light));
  h.add(static_cast<std::uint64_t>(state.instances.size()));
  if (!state.instances.empty()) h.add(instances.sum);
  // Only when there are any: a state without them hashes as it did before they were.
  if (!state.point_lights.empty()) {
    h.add(static_cast<std::uint64_t>(state.point_lights.size()));
    for (const auto& [index, light] : state.point_lights) {
      h.add(static_cast<std::uint64_t>(index));
      h.add(light);
    }
  }
  return h.value();
}

wire::Snapshot to_snapshot(const SceneState& state) {
  wire::Snapshot snapshot;
  for (const auto& [id, object] : state.objects) to_wire(id, object, *snapshot.add_objects());
  to_wire(state, *snapshot.mutable_viewer());
  snapshot.mutable_lights_off()->Add(state.lights_off.begin(), state.lights_off.end());
  for (const auto& [id, instance] : state.instances) to_wire(id, instance, *snapshot.add_instances());
  for (const auto& [index, light] : state.point_lights) to_wire(index, light, *snapshot.add_point_lights());
  return snapshot;
}

Result<SceneState> from_snapshot(const wire::Snapshot& snapshot) {
  SceneState state;
  for (const auto& o : snapshot.objects()) {
    auto object = from_wire(o);
    if (!object) return Error{object.error()};
    if (!state.objects.emplace(o.id(), object.value()).second) {
      return Error{"snapshot lists object " + std::to_string(o.id()) + " twice"};
    }
  }
  auto viewer = viewer_from_wire(snapshot.viewer());
  if (!viewer) return Error{viewer.error()};
  set_viewer(state, viewer.value());
  for (std::uint32_t light : snapshot.lights_off()) {
    if (!state.lights_off.insert(light).second) {
      return Error{"snapshot lists light " + std::to_string(light) + " as off twice"};
    }
  }
  std::vector<Named> ids;
  for (const auto& i : snapshot.instances()) {
    auto instance = from_wire(i);
    if (!instance) return Error{"snapshot: " + instance.error()};
    const auto [placed, added] = state.instances.emplace(std::move(instance).value());
    if (!added) return Error{"snapshot lists instance " + i.id() + " twice"};
    ids.emplace_back(&placed->first, &placed->second);
  }
  const auto lookup = [&](const std::string& id) -> const InstanceState* {
    const auto found = state.instances.find(id);
    return found == state.instances.end() ? nullptr : &found->second;
  };
  if (auto ok = check_parents(ids, lookup); !ok) return Error{"snapshot: " + ok.error()};
  for (const auto& l : snapshot.point_lights()) {
    auto light = from_wire(l);
    if (!light) return Error{"snapshot: " + light.error()};
    if (!state.point_lights.insert(light.value()).second) {
      return Error{"snapshot lists point light " + std::to_string(l.light()) + " twice"};
    }
  }
  if (state.point_lights.size() > kMaxAddedLights) {
    return Error{"snapshot: more than " + std::to_string(kMaxAddedLights) + " point lights added"};
  }
  return state;
}

namespace {

// An instance as `after` where it was `before` (none: it is new): changed,
// moved (its pose alone changed), or nothing when it is the same.
void add_instance_change(const std::string& id, const InstanceState* before, const InstanceState& after,
                         wire::StateDelta& delta) {
  if (before == nullptr || !identical_but_pose(*before, after)) {
    to_wire(id, after, *delta.add_instances_changed());
  } else if (!identical(before->pose, after.pose)) {
    wire::InstanceMove& moved = *delta.add_instances_moved();
    moved.set_id(id);
    pose_to_wire(after.pose, *moved.mutable_pose());
  }
}

}  // namespace

wire::StateDelta make_instance_delta(const SceneState& before,
                                     const std::map<std::string, std::optional<InstanceState>>& after) {
  wire::StateDelta delta;
  // Both by id: walked side by side.
  auto was = before.instances.begin();
  for (const auto& [id, instance] : after) {
    while (was != before.instances.end() && was->first < id) ++was;
    const InstanceState* old = was != before.instances.end() && was->first == id ? &was->second : nullptr;
    if (instance) {
      add_instance_change(id, old, *instance, delta);
    } else if (old != nullptr) {
      delta.add_instances_removed(id);
    }
  }
  return delta;
}

wire::StateDelta make_delta(const SceneState& before, const SceneState& after, bool instances) {
  wire::StateDelta delta;
  for (const auto& [id, object] : after.objects) {
    const auto old = before.objects.find(id);
    if (old == before.objects.end() || !identical(old->second, object)) to_wire(id, object, *delta.add_changed());
  }
  for (const auto& [id, object] : before.objects) {
    if (!after.objects.contains(id)) delta.add_removed(id);
  }
  if (!identical(before.eye_now, after.eye_now) || !identical(before.eye_next, after.eye_next) ||
      !identical(before.head_now, after.head_now) || !identical(before.head_next, after.head_next) ||
      !identical(before.navigation, after.navigation)) {
    to_wire(after, *delta.mutable_viewer());
  }
  for (std::uint32_t light : after.lights_off) {
    if (!before.lights_off.contains(light)) delta.add_lights_off(light);
  }
  for (std::uint32_t light : before.lights_off) {
    if (!after.lights_off.contains(light)) delta.add_lights_on(light);
  }
  // Both by id: walked side by side, not searched (thousands of instances).
  static const Instances kNone;
  const Instances& walked = instances ? after.instances : kNone;
  auto old = before.instances.begin();
  for (const auto& [id, instance] : walked) {
    for (; old != before.instances.end() && old->first < id; ++old) delta.add_instances_removed(old->first);
    const bool was_there = old != before.instances.end() && old->first == id;
    add_instance_change(id, was_there ? &old->second : nullptr, instance, delta);
    if (was_there) ++old;
  }
  for (; instances && old != before.instances.end(); ++old) delta.add_instances_removed(old->first);
  for (const auto& [index, light] : after.point_lights) {
    const auto was = before.point_lights.find(index);
    if (was == before.point_lights.end() || !identical(was->second, light)) {
      to_wire(index, light, *delta.add_point_lights_set());
    }
  }
  for (const auto& [index, light] : before.point_lights) {
    if (!after.point_lights.contains(index)) delta.add_point_lights_removed(index);
  }
  return delta;
}

namespace {

// apply_delta, keeping the instances' hash where `keep` says.
Result<void> apply(SceneState& state, const wire::StateDelta& delta, InstancesHash& instances, bool keep) {
  // Check everything first so a bad delta leaves the state as it was.
  std::vector<std::pair<std::uint32_t, ObjectState>> changed;
  changed.reserve(static_cast<std::size_t>(delta.changed_size()));
  for (const auto& o : delta.changed()) {
    auto object = from_wire(o);
    if (!object) return Error{"delta: " + object.error()};
    changed.emplace_back(o.id(), object.value());
  }
  for (std::uint32_t id : delta.removed()) {
    if (!state.objects.contains(id))
      return Error{"delta removes object " + std::to_string(id) + ", which does not exist"};
  }
  ViewerPair viewer{state.eye_now, state.eye_next, state.head_now, state.head_next, state.navigation};
  if (delta.has_viewer()) {
    auto moved = viewer_from_wire(delta.viewer());
    if (!moved) return Error{"delta: " + moved.error()};
    viewer = moved.value();
  }
  std::set<std::uint32_t> lights_off = state.lights_off;
  for (std::uint32_t light : delta.lights_off()) {
    if (!lights_off.insert(light).second) {
      return Error{"delta switches off light " + std::to_string(light) + ", which is off already"};
    }
  }
  for (std::uint32_t light : delta.lights_on()) {
    // Against the state before the delta, so one delta cannot switch a light off and on.
    if (!state.lights_off.contains(light) || lights_off.erase(light) == 0) {
      return Error{"delta switches on light " + std::to_string(light) + ", which is not off"};
    }
  }

  // Copied only when the delta touches them: most frames do not.
  std::optional<std::map<std::uint32_t, PointLightState>> point_lights;
  if (delta.point_lights_set_size() > 0 || delta.point_lights_removed_size() > 0) {
    point_lights = state.point_lights;
    std::set<std::uint32_t> named;
    for (const auto& l : delta.point_lights_set()) {
      auto light = from_wire(l);
      if (!light) return Error{"delta: " + light.error()};
      if (!named.insert(l.light()).second)
        return Error{"delta sets point light " + std::to_string(l.light()) + " twice"};
      point_lights->insert_or_assign(light.value().first, light.value().second);
    }
    for (std::uint32_t index : delta.point_lights_removed()) {
      if (!named.insert(index).second || point_lights->erase(index) == 0) {
        return Error{"delta removes point light " + std::to_string(index) +
                     ", which it cannot: it is not there, set too, or removed twice"};
      }
    }
    if (point_lights->size() > kMaxAddedLights) {
      return Error{"delta: more than " + std::to_string(kMaxAddedLights) + " point lights added"};
    }
  }

  // By id, ascending (as the master sends them: then no sort), so that finding
  // one is a binary search and the state takes them in order, each next to
  // the last: a frame that moves a thousand instances compared ids in maps
  // for a tenth of a node's time.
  std::vector<std::pair<std::string, InstanceState>> instances_changed;
  instances_changed.reserve(static_cast<std::size_t>(delta.instances_changed_size()));
  for (const auto& i : delta.instances_changed()) {
    auto instance = from_wire(i);
    if (!instance) return Error{"delta: " + instance.error()};
    instances_changed.push_back(std::move(instance).value());
  }
  const auto by_id = [](const auto& a, const auto& b) { return a.first < b.first; };
  if (!std::is_sorted(instances_changed.begin(), instances_changed.end(), by_id)) {
    std::stable_sort(instances_changed.begin(), instances_changed.end(), by_id);
  }
  if (const auto twice = std::adjacent_find(instances_changed.begin(), instances_changed.end(),
                                            [](const auto& a, const auto& b) { return a.first == b.first; });
      twice != instances_changed.end()) {
    return Error{"delta changes instance " + twice->first + " twice"};
  }
  const auto changed_instance = [&](const std::string& id) -> const InstanceState* {
    const auto at = std::lower_bound(instances_changed.begin(), instances_changed.end(), id,
                                     [](const auto& entry, const std::string& key) { return entry.first < key; });
    return at != instances_changed.end() && at->first == id ? &at->second : nullptr;
  };
  std::set<std::string> instances_removed;
  for (const std::string& id : delta.instances_removed()) {
    if (!is_instance_id(id)) return Error{"delta removes an instance whose id is not one"};
    if (!state.instances.contains(id) || changed_instance(id) != nullptr || !instances_removed.insert(id).second) {
      return Error{"delta removes instance " + id +
                   ", which it cannot: it is not there, changed too, or removed twice"};
    }
  }
  if (!instances_changed.empty() || !instances_removed.empty()) {
    const auto lookup = [&](const std::string& id) -> const InstanceState* {
      if (const InstanceState* changed_here = changed_instance(id)) return changed_here;
      const auto found = state.instances.find(id);
      return found == state.instances.end() || instances_removed.contains(id) ? nullptr : &found->second;
    };
    std::vector<Named> ids;
    ids.reserve(instances_changed.size());
    for (const auto& [id, instance] : instances_changed) ids.emplace_back(&id, &instance);
    if (!instances_removed.empty()) {  // what a removal leaves behind
      for (const auto& [id, instance] : state.instances) {
        if (!instances_removed.contains(instance.parent)) continue;
        if (const InstanceState* left = lookup(id)) ids.emplace_back(&id, left);
      }
    }
    if (auto ok = check_parents(ids, lookup); !ok) return Error{"delta: " + ok.error()};
  }
  auto moves = moves_from_wire(delta, state.instances, changed_instance, instances_removed);
  if (!moves) return Error{moves.error()};

  for (auto& [id, object] : changed) state.objects.insert_or_assign(id, object);
  // Each instance's hash out of the sum as it was, and in as it is.
  const auto unhash = [&](const std::string& id, const InstanceState& instance) {
    if (keep) instances.sum -= instance_hash(id, instance);
  };
  const auto rehash = [&](const std::string& id, const InstanceState& instance) {
    if (keep) instances.sum += instance_hash(id, instance);
  };
  // In order, each hinted at the one after the last: next to it when they are neighbours.
  auto hint = state.instances.begin();
  for (auto& [id, instance] : instances_changed) {
    auto at = hint != state.instances.end() && hint->first == id ? hint : state.instances.find(id);
    if (at != state.instances.end()) {
      unhash(id, at->second);
      at->second = std::move(instance);
    } else {
      at = state.instances.emplace_hint(hint, id, std::move(instance));
    }
    rehash(at->first, at->second);
    hint = std::next(at);
  }
  for (auto& [at, pose] : moves.value()) {
    unhash(at->first, at->second);
    at->second.pose = pose;
    rehash(at->first, at->second);
  }
  for (const std::string& id : instances_removed) {
    const auto at = state.instances.find(id);
    unhash(id, at->second);
    state.instances.erase(at);
  }
  for (std::uint32_t id : delta.removed()) state.objects.erase(id);
  set_viewer(state, viewer);
  state.lights_off = std::move(lights_off);
  if (point_lights) state.point_lights = std::move(*point_lights);
  return {};
}

}  // namespace

Result<void> apply_delta(SceneState& state, const wire::StateDelta& delta) {
  InstancesHash unused;
  return apply(state, delta, unused, false);
}

Result<void> apply_delta(SceneState& state, const wire::StateDelta& delta, InstancesHash& instances) {
  return apply(state, delta, instances, true);
}

}  // namespace optique::scene
