#pragma once
// How the config file spells each enum of the installation: one table per
// enum, read by the check (the names it accepts, in its messages), the build
// (text to value) and to_string (value to text, for logs and jobs).

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "config/installation.h"

namespace optique::config {

template <class E>
struct Named {
  std::string_view name;
  E value;
};

// The first entry of each is the default an empty field means.
inline constexpr std::array<Named<Eye>, 3> kEyeNames{{{"mono", Eye::mono}, {"left", Eye::left}, {"right", Eye::right}}};
inline constexpr std::array<Named<RenderMethod>, 2> kRenderMethodNames{
    {{"single-pass", RenderMethod::single_pass}, {"two-pass", RenderMethod::two_pass}}};
inline constexpr std::array<Named<ContentRole>, 4> kContentRoleNames{{{"full", ContentRole::full},
                                                                      {"lights", ContentRole::lights},
                                                                      {"focus", ContentRole::focus},
                                                                      {"defocus", ContentRole::defocus}}};
inline constexpr std::array<Named<StragglerPolicy>, 2> kStragglerPolicyNames{
    {{"present", StragglerPolicy::present}, {"drop", StragglerPolicy::drop}}};
inline constexpr std::array<Named<OutputKind>, 2> kOutputKindNames{
    {{"headless", OutputKind::headless}, {"window", OutputKind::window}}};

// The value `name` spells; the default (the first) for an empty name; nothing
// for a name the table does not have.
template <class E, std::size_t N>
[[nodiscard]] constexpr std::optional<E> from_name(const std::array<Named<E>, N>& table, std::string_view name) {
  if (name.empty()) return table.front().value;
  for (const Named<E>& entry : table) {
    if (entry.name == name) return entry.value;
  }
  return std::nullopt;
}

template <class E, std::size_t N>
[[nodiscard]] constexpr std::string_view name_of(const std::array<Named<E>, N>& table, E value) {
  for (const Named<E>& entry : table) {
    if (entry.value == value) return entry.name;
  }
  return table.front().name;
}

// The names, in the table's order (for "expected one of: …").
template <class E, std::size_t N>
[[nodiscard]] std::vector<std::string_view> names_of(const std::array<Named<E>, N>& table) {
  std::vector<std::string_view> names;
  for (const Named<E>& entry : table) names.push_back(entry.name);
  return names;
}

}  // namespace optique::config
