// How the config file spells each enum: config/names.h.

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "config/names.h"

namespace optique::config {
namespace {

// Every name and every value once; each name back to its value and the
// value back to its name; an empty name is the first (the default).
template <class E, std::size_t N>
void expect_one_to_one(const std::array<Named<E>, N>& table) {
  std::set<std::string_view> names;
  std::set<E> values;
  for (const Named<E>& entry : table) {
    EXPECT_TRUE(names.insert(entry.name).second) << entry.name << " twice";
    EXPECT_TRUE(values.insert(entry.value).second) << entry.name << "'s value twice";
    EXPECT_EQ(from_name(table, entry.name), entry.value) << entry.name;
    EXPECT_EQ(name_of(table, entry.value), entry.name);
  }
  EXPECT_EQ(from_name(table, ""), table.front().value);
  EXPECT_EQ(from_name(table, "no-such-name"), std::nullopt);
}

TEST(ConfigNames, EveryTableIsOneToOne) {
  expect_one_to_one(kEyeNames);
  expect_one_to_one(kRenderMethodNames);
  expect_one_to_one(kContentRoleNames);
  expect_one_to_one(kStragglerPolicyNames);
  expect_one_to_one(kOutputKindNames);
}

// The spellings docs/configuration.md gives, and the defaults an empty field means.
TEST(ConfigNames, TheDocumentedSpellings) {
  EXPECT_EQ(from_name(kEyeNames, "left"), Eye::left);
  EXPECT_EQ(from_name(kEyeNames, "right"), Eye::right);
  EXPECT_EQ(from_name(kEyeNames, ""), Eye::mono);
  EXPECT_EQ(from_name(kRenderMethodNames, "two-pass"), RenderMethod::two_pass);
  EXPECT_EQ(from_name(kRenderMethodNames, ""), RenderMethod::single_pass);
  EXPECT_EQ(from_name(kContentRoleNames, "lights"), ContentRole::lights);
  EXPECT_EQ(from_name(kContentRoleNames, "focus"), ContentRole::focus);
  EXPECT_EQ(from_name(kContentRoleNames, "defocus"), ContentRole::defocus);
  EXPECT_EQ(from_name(kContentRoleNames, ""), ContentRole::full);
  EXPECT_EQ(from_name(kStragglerPolicyNames, "drop"), StragglerPolicy::drop);
  EXPECT_EQ(from_name(kStragglerPolicyNames, ""), StragglerPolicy::present);
  EXPECT_EQ(from_name(kOutputKindNames, "window"), OutputKind::window);
  EXPECT_EQ(from_name(kOutputKindNames, ""), OutputKind::headless);
  EXPECT_EQ(to_string(RenderMethod::two_pass), "two-pass");
}

}  // namespace
}  // namespace optique::config
