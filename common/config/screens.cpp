// The screens: planar rectangles, each with its own frame.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "config/sections.h"
#include "util/number_text.h"

namespace optique::config {

std::vector<Screen> parse_screens(const schema::Installation& installation, Checker& check) {
  using util::number_text;
  if (installation.screens().empty()) check.fail("screens", "at least one screen is needed");
  std::vector<Screen> screens;
  std::set<std::string> ids;
  for (int i = 0; i < installation.screens_size(); ++i) {
    const schema::Screen& s = installation.screens(i);
    const std::string at = "screens[" + std::to_string(i) + "]";
    Screen screen;
    screen.id = s.id();
    check.id(at + ".id", s.id(), ids, "screen");
    if (const auto origin = check.vec3(at + ".origin", s.origin())) screen.origin = *origin;
    const auto right = check.vec3(at + ".right", s.right());
    const auto up = check.vec3(at + ".up", s.up());
    const bool right_unit = right && check.unit(at + ".right", *right);
    const bool up_unit = up && check.unit(at + ".up", *up);
    if (right && up && std::abs(glm::dot(*right, *up)) > 1e-3) {
      check.fail(at + ".up", "must be perpendicular to right (dot product " + number_text(glm::dot(*right, *up)) + ")");
    }
    if (right_unit) screen.right = glm::normalize(*right);
    if (up_unit) screen.up = glm::normalize(*up);
    check.positive(at + ".width", s.width());
    check.positive(at + ".height", s.height());
    check.non_negative(at + ".pixels_per_metre", s.pixels_per_metre());
    screen.width = s.width();
    screen.height = s.height();
    screen.pixels_per_metre = s.pixels_per_metre() != 0.0 ? s.pixels_per_metre() : defaults::kPixelsPerMetre;
    screens.push_back(std::move(screen));
  }
  return screens;
}

std::optional<std::size_t> find_screen(const std::vector<Screen>& screens, const std::string& id) {
  for (std::size_t i = screens.size(); i-- > 0;) {
    if (screens[i].id == id) return i;
  }
  return std::nullopt;
}

bool every_screen_named(const std::vector<Screen>& screens) {
  return std::all_of(screens.begin(), screens.end(), [](const Screen& s) { return !s.id.empty(); });
}

}  // namespace optique::config
