#include "master/run/stacked_groups.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <set>

#include "config/light_list.h"
#include "config/projector_groups.h"
#include "scene/light_coverage.h"

namespace optique::master {
namespace {

std::string group_name(const config::Installation& inst, const StackedGroup& group) {
  return "stacked group on screen '" + inst.screens[group.screen].id + "' (eye " +
         std::string(config::to_string(group.eye)) + ")";
}

std::string lights_path(std::size_t projector) {
  return "projectors[" + std::to_string(projector) + "].content.lights";
}

// The group's layers: the first member of each, and the members it stands for.
std::vector<std::vector<std::size_t>> layers_of(const config::Installation& inst, const StackedGroup& group) {
  std::vector<std::vector<std::size_t>> layers;
  for (std::size_t member : group.members) {
    auto layer = std::find_if(layers.begin(), layers.end(), [&](const std::vector<std::size_t>& l) {
      return config::same_layer(inst.projectors[l.front()], inst.projectors[member]);
    });
    if (layer != layers.end()) {
      layer->push_back(member);
    } else {
      layers.push_back({member});
    }
  }
  return layers;
}

}  // namespace

std::vector<StackedGroup> lighting_groups(const config::Installation& inst) {
  std::vector<StackedGroup> groups;
  for (std::size_t i = 0; i < inst.projectors.size(); ++i) {
    const config::Projector& p = inst.projectors[i];
    if (p.content.role != config::ContentRole::lights) continue;
    auto group = std::find_if(groups.begin(), groups.end(), [&](const StackedGroup& g) {
      return config::same_screen_image(inst.projectors[g.members.front()], p);
    });
    if (group == groups.end()) {
      groups.push_back({p.screen, p.eye, {}, p.content.automatic});
      group = std::prev(groups.end());
    }
    group->members.push_back(i);
  }
  return groups;
}

std::vector<config::Problem> check_lighting_groups(const config::Installation& inst, std::size_t light_count) {
  std::vector<config::Problem> problems;
  for (const StackedGroup& group : lighting_groups(inst)) {
    const auto projector = [&](std::size_t i) -> const config::Projector& { return inst.projectors[i]; };
    bool mixed = false;
    for (std::size_t member : group.members) {
      if (projector(member).content.automatic != group.automatic) mixed = true;
    }
    if (mixed) {
      problems.push_back({lights_path(group.members.front()),
                          "the " + group_name(inst, group) +
                              " mixes \"auto\" with listed lights: use \"auto\" for all its projectors, or list "
                              "the lights of each"});
      continue;
    }
    if (group.automatic) continue;  // the master shares them out: nothing can be missing or twice

    std::vector<std::string> drawn_by(light_count);
    std::vector<std::string> ambient_carriers;
    bool parsed = true;
    for (const std::vector<std::size_t>& layer : layers_of(inst, group)) {
      const config::Projector& first = projector(layer.front());
      if (auto beyond = config::lights_beyond(first.content.lights, light_count)) {
        problems.push_back({lights_path(layer.front()), *beyond});
        parsed = false;
        continue;
      }
      for (std::uint32_t light : first.content.lights) {
        if (!drawn_by[light].empty()) {
          problems.push_back({lights_path(layer.front()), "light " + std::to_string(light) + " is drawn twice in the " +
                                                              group_name(inst, group) + ", by '" + drawn_by[light] +
                                                              "' and '" + first.id +
                                                              "': give each light to exactly one projector"});
        } else {
          drawn_by[light] = first.id;
        }
      }
      if (first.content.ambient) ambient_carriers.push_back(first.id);
    }
    if (parsed) {
      std::vector<std::uint32_t> missing;
      for (std::size_t light = 0; light < light_count; ++light) {
        if (drawn_by[light].empty()) missing.push_back(static_cast<std::uint32_t>(light));
      }
      if (!missing.empty()) {
        problems.push_back({lights_path(group.members.front()), "the " + group_name(inst, group) + " draws no light " +
                                                                    config::format_light_list(missing) +
                                                                    " of the scene's " + std::to_string(light_count) +
                                                                    ": give each light to exactly one projector"});
      }
    }
    const std::string ambient_path = "projectors[" + std::to_string(group.members.front()) + "].content.ambient";
    if (ambient_carriers.empty()) {
      problems.push_back({ambient_path, "no projector of the " + group_name(inst, group) +
                                            " carries ambient and emissive light: set ambient on exactly one"});
    } else if (ambient_carriers.size() > 1) {
      problems.push_back({ambient_path, "ambient and emissive light are carried twice in the " +
                                            group_name(inst, group) + ", by '" + ambient_carriers[0] + "' and '" +
                                            ambient_carriers[1] + "': set ambient on exactly one projector"});
    }
  }
  return problems;
}

std::map<std::size_t, LightShare> listed_shares(const config::Installation& inst, std::size_t light_count) {
  std::map<std::size_t, LightShare> shares;
  for (const StackedGroup& group : lighting_groups(inst)) {
    if (group.automatic) continue;
    for (std::size_t member : group.members) {
      const config::Content& content = inst.projectors[member].content;
      assert(!config::lights_beyond(content.lights, light_count));
      (void)light_count;
      shares[member] = {content.lights, content.ambient};
    }
  }
  return shares;
}

std::vector<double> group_light_costs(const config::Installation& inst, const StackedGroup& group,
                                      const scene::SceneDefinition& scene, const scene::SceneState& state,
                                      const glm::dvec3& eye) {
  const config::Screen& screen = inst.screens[group.screen];
  geometry::ScreenRect area{{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()},
                            {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()}};
  for (std::size_t member : group.members) {
    for (const glm::dvec2& corner : inst.projectors[member].geometry().lit_quad()) {
      area.min = glm::min(area.min, corner);
      area.max = glm::max(area.max, corner);
    }
  }
  const geometry::ScreenRect usable = screen.area();
  area.min = glm::clamp(area.min, usable.min, usable.max);
  area.max = glm::clamp(area.max, usable.min, usable.max);
  scene::CoverageGrid grid;
  grid.eye = eye;
  grid.corner = screen.point(area.min);
  grid.across = area.width() * screen.right;
  grid.up = area.height() * screen.up;
  return scene::light_coverage(scene, state, grid);
}

namespace {

// A group's members that are up: their places in the group and their pixels.
struct LiveMembers {
  std::vector<std::size_t> places;
  std::vector<double> pixels;
};

LiveMembers live_members(const config::Installation& inst, const StackedGroup& group, const std::vector<bool>& live) {
  assert(live.size() == group.members.size());
  LiveMembers members;
  for (std::size_t k = 0; k < group.members.size(); ++k) {
    if (!live[k]) continue;
    const config::Projector& p = inst.projectors[group.members[k]];
    members.places.push_back(k);
    members.pixels.push_back(static_cast<double>(p.width) * p.height);
  }
  return members;
}

// One share per member of the group: the live members' by cost, nothing for the
// others; the lights that are off, and the indices that hold none, go to nobody.
std::vector<LightShare> shares_for(const StackedGroup& group, const LiveMembers& members,
                                   const std::vector<double>& costs, const scene::SceneDefinition& scene,
                                   const scene::SceneState& state) {
  std::vector<LightShare> shares(group.members.size());
  if (members.places.empty()) return shares;
  const auto lights = scene::frame_lights(scene, state);
  assert(lights.size() == costs.size());
  std::vector<std::uint32_t> shining;
  std::vector<double> shining_costs;
  for (std::size_t light = 0; light < costs.size(); ++light) {
    if (!lights[light] || state.lights_off.contains(static_cast<std::uint32_t>(light))) continue;
    shining.push_back(static_cast<std::uint32_t>(light));
    shining_costs.push_back(costs[light]);
  }
  std::vector<LightShare> live_shares = share_lights(shining_costs, members.pixels, kBaseCost, kAmbientCost);
  for (std::size_t i = 0; i < members.places.size(); ++i) {
    LightShare& share = live_shares[i];
    for (std::uint32_t& light : share.lights) light = shining[light];  // still ascending
    shares[members.places[i]] = std::move(share);
  }
  return shares;
}

}  // namespace

std::vector<LightShare> automatic_shares(const config::Installation& inst, const StackedGroup& group,
                                         const std::vector<bool>& live, const scene::SceneDefinition& scene,
                                         const scene::SceneState& state, const glm::dvec3& eye) {
  return shares_for(group, live_members(inst, group, live), group_light_costs(inst, group, scene, state, eye), scene,
                    state);
}

LightPlan::LightPlan(const config::Installation& installation, const scene::SceneDefinition& scene)
    : installation_(installation),
      scene_(scene),
      groups_(lighting_groups(installation)),
      listed_(listed_shares(installation, scene.lights.size())),
      shares_(listed_) {}

bool LightPlan::rebalance(const std::vector<bool>& up, const scene::SceneState& state, const glm::dvec3& eye,
                          bool force) {
  // A split this much faster (modelled) than the current one is worth switching
  // to; smaller gains would let the split flicker between near-equal choices.
  constexpr double kWorthwhileGain = 0.05;
  bool changed = false;
  for (const StackedGroup& group : groups_) {
    if (!group.automatic) {
      changed = listed_with_added(group, state) || changed;
      continue;
    }
    std::vector<bool> live;
    for (std::size_t member : group.members) live.push_back(up[member]);
    const LiveMembers members = live_members(installation_, group, live);
    const std::vector<double> costs = group_light_costs(installation_, group, scene_, state, eye);
    std::vector<LightShare> proposed = shares_for(group, members, costs, scene_, state);
    bool differs = false;
    for (std::size_t k = 0; k < group.members.size(); ++k) {
      const auto current = shares_.find(group.members[k]);
      differs = differs || current == shares_.end() || current->second != proposed[k];
    }
    if (!differs) continue;
    if (!force && !members.places.empty()) {
      // Both splits' modelled times under today's costs.
      std::vector<LightShare> current;
      std::vector<LightShare> candidate;
      bool complete = true;
      for (std::size_t k : members.places) {
        const auto found = shares_.find(group.members[k]);
        complete = complete && found != shares_.end();
        current.push_back(found != shares_.end() ? found->second : LightShare{});
        candidate.push_back(proposed[k]);
      }
      const auto slowest = [&](const std::vector<LightShare>& shares) {
        const std::vector<double> t = modelled_times(costs, members.pixels, kBaseCost, kAmbientCost, shares);
        return *std::max_element(t.begin(), t.end());
      };
      if (complete && slowest(candidate) > slowest(current) * (1.0 - kWorthwhileGain)) continue;
    }
    for (std::size_t k = 0; k < group.members.size(); ++k) shares_[group.members[k]] = std::move(proposed[k]);
    changed = true;
  }
  return changed;
}

// A group whose config lists its lights: the lights applications add are
// drawn by the projector that carries the ambient light (one does: checked at
// the start), beside its listed ones.
bool LightPlan::listed_with_added(const StackedGroup& group, const scene::SceneState& state) {
  bool changed = false;
  for (std::size_t member : group.members) {
    LightShare share = listed_.at(member);
    if (share.ambient) {
      for (const auto& [index, light] : state.point_lights) {
        if (index >= scene_.lights.size()) share.lights.push_back(index);  // after the listed: ascending
      }
    }
    LightShare& current = shares_[member];
    if (current != share) {
      current = std::move(share);
      changed = true;
    }
  }
  return changed;
}

const LightShare* LightPlan::share(std::size_t projector) const {
  const auto found = shares_.find(projector);
  return found == shares_.end() ? nullptr : &found->second;
}

}  // namespace optique::master
