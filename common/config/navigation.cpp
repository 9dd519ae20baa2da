#include "config/navigation.h"

#include <array>

#include <glm/geometric.hpp>

#include "config/checker.h"
#include "util/number_text.h"

namespace optique::config {

namespace {

constexpr std::array<Named<NavigationMode>, 2> kModes{
    {{"none", NavigationMode::none}, {"flystick", NavigationMode::flystick}}};
// A Flystick 2 has 6 buttons; the format allows more (tracking/dtrack.h's 64).
constexpr std::uint32_t kMostButtons = 64;

// A number in (0, most], or `fallback` when left at 0.
double speed_at(Checker& check, const std::string& path, double value, double fallback, double most, const char* unit) {
  if (value == 0.0) return fallback;
  if (!check.finite(path, value)) return fallback;
  if (value < 0.0 || value > most) {
    check.fail(path,
               "must be in (0, " + util::number_text(most) + "] " + unit + " (got " + util::number_text(value) + ")");
    return fallback;
  }
  return value;
}

// A unit vector at `path`, or `fallback` when absent.
glm::dvec3 direction_at(Checker& check, const std::string& path, const google::protobuf::RepeatedField<double>& value,
                        glm::dvec3 fallback) {
  if (value.empty()) return fallback;
  const auto v = check.vec3(path, value);
  if (!v || !check.unit(path, *v)) return fallback;
  return glm::normalize(*v);
}

}  // namespace

std::string_view to_string(NavigationMode mode) { return name_of(kModes, mode); }

Navigation parse_navigation(const schema::Navigation& n, const std::string& path, std::vector<Problem>& problems) {
  Checker check(problems);
  Navigation out;
  if (!n.mode().empty()) {
    if (const auto mode = check.name(path + ".mode", n.mode(), kModes)) out.mode = *mode;
  }
  out.flystick = n.flystick();
  out.speed = speed_at(check, path + ".speed", n.speed(), defaults::kNavigationSpeed, kMostNavigationSpeed, "m/s");
  out.turn_speed = speed_at(check, path + ".turn_speed", n.turn_speed(), defaults::kNavigationTurnSpeed,
                            kMostNavigationTurnSpeed, "degrees/s");
  if (n.reset_button() >= kMostButtons) {
    check.fail(path + ".reset_button",
               "must be below " + std::to_string(kMostButtons) + " (got " + std::to_string(n.reset_button()) + ")");
  } else if (n.has_reset_button()) {
    out.reset_button = n.reset_button();
  }
  if (n.has_dead_zone() && check.finite(path + ".dead_zone", n.dead_zone())) {
    if (n.dead_zone() < 0.0 || n.dead_zone() > kMostDeadZone) {
      check.fail(path + ".dead_zone", "must be in [0, " + util::number_text(kMostDeadZone) + "] (got " +
                                          util::number_text(n.dead_zone()) + ")");
    } else {
      out.dead_zone = n.dead_zone();
    }
  }
  out.up = direction_at(check, path + ".up", n.up(), out.up);
  out.pointer = direction_at(check, path + ".pointer", n.pointer(), out.pointer);
  return out;
}

}  // namespace optique::config
