#pragma once
// Stacked lighting groups: projectors of role "lights" on the same screen for the
// same eye, whose light adds into one image. Each light must be drawn by exactly
// one layer of a group (projectors with identical content are one layer: tiles of
// it), ambient and emissive light by exactly one; or the master shares the lights
// out itself ("auto"). Checked before anything starts, since a light drawn twice
// or never is a wrong picture, not a slow one.

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "config/installation.h"
#include "config/problem.h"
#include "master/run/light_share.h"
#include "optique/config.pb.h"
#include "scene/definition.h"
#include "scene/state.h"

namespace optique::master {

struct StackedGroup {
  std::size_t screen = 0;  // index into Installation.screens
  config::Eye eye = config::Eye::mono;
  std::vector<std::size_t> members;  // indices into Installation.projectors, config order
  bool automatic = false;            // lights "auto": the master shares them out
};

[[nodiscard]] std::vector<StackedGroup> lighting_groups(const config::Installation& installation);

// Every problem with the groups' light lists, naming the field or the group: a
// list that names a light the scene lacks, "auto" mixed with lists, a light
// drawn by no layer or by two, no ambient carrier or two.
[[nodiscard]] std::vector<config::Problem> check_lighting_groups(const config::Installation& installation,
                                                                 std::size_t light_count);

// The shares the config lists, by projector index (only for groups that list
// them). Runs on an installation that check_lighting_groups accepts.
[[nodiscard]] std::map<std::size_t, LightShare> listed_shares(const config::Installation& installation,
                                                              std::size_t light_count);

// The cost model of the automatic split, in units of a light that reaches every
// pixel (light_share.h): a node's pixels cost kBaseCost before any light (the
// pass over the scene, the material, the output pass) — fitted to node draw
// times on llvmpipe, docs/bench/lighting.md: about three lights' worth — and the
// ambient and emissive terms two multiply-adds.
inline constexpr double kBaseCost = 3.0;
inline constexpr double kAmbientCost = 0.05;

// Each light's estimated cost to the group: its coverage of the area the group
// lights (the members' lit quads, bounded, within the screen) seen from `eye`.
[[nodiscard]] std::vector<double> group_light_costs(const config::Installation& installation, const StackedGroup& group,
                                                    const scene::SceneDefinition& scene, const scene::SceneState& state,
                                                    const glm::dvec3& eye);

// An automatic group's shares among its live members (`live[k]` for members[k]),
// by estimated cost: each light's coverage of the group's screen area seen from
// `eye`, times each member's pixels. Members that are not live get nothing, and
// the lights the state has switched off go to nobody.
[[nodiscard]] std::vector<LightShare> automatic_shares(const config::Installation& installation,
                                                       const StackedGroup& group, const std::vector<bool>& live,
                                                       const scene::SceneDefinition& scene,
                                                       const scene::SceneState& state, const glm::dvec3& eye);

// Who draws which lights, for the whole installation, as the nodes come and go:
// listed shares are fixed, but for the lights applications add, which the
// ambient carrier of the group draws; an automatic group's lights go to the members that
// are up, by estimated cost, and are shared out again when a member comes or
// goes, or when the scene has moved enough that another split would finish
// clearly sooner.
class LightPlan {
 public:
  LightPlan(const config::Installation& installation, const scene::SceneDefinition& scene);

  // Shares the automatic groups' lights among the projectors that are up
  // (`up[i]` for projector i), at `state` seen from `eye`. `force`: share them
  // out anew even if the modelled gain is small (a member came or went, a light
  // was switched on or off).
  // Returns whether any share changed.
  bool rebalance(const std::vector<bool>& up, const scene::SceneState& state, const glm::dvec3& eye, bool force);

  // The share of projector i; nothing for a projector whose role is not "lights".
  [[nodiscard]] const LightShare* share(std::size_t projector) const;

 private:
  bool listed_with_added(const StackedGroup& group, const scene::SceneState& state);

  const config::Installation& installation_;
  const scene::SceneDefinition& scene_;
  std::vector<StackedGroup> groups_;
  std::map<std::size_t, LightShare> listed_;  // the shares the config lists (listed_shares)
  std::map<std::size_t, LightShare> shares_;
};

}  // namespace optique::master
