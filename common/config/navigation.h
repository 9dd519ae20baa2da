#pragma once
// Built-in navigation, checked and typed (`viewer.navigation`): a flystick
// flies the installation through the world with no application of the user's
// own. The joystick forward and back moves along where the wand points, sideways
// turns about the world's vertical through the eyes; a button brings the
// installation back to where the navigation started.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "config/defaults.h"
#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::config {

enum class NavigationMode { none, flystick };
[[nodiscard]] std::string_view to_string(NavigationMode mode);

// The fastest a flystick may fly and turn: beyond these a CAVE's viewer is
// sick, not travelling.
inline constexpr double kMostNavigationSpeed = 100.0;      // m/s
inline constexpr double kMostNavigationTurnSpeed = 360.0;  // degrees/s
inline constexpr double kMostDeadZone = 0.9;

struct Navigation {
  NavigationMode mode = NavigationMode::none;
  std::uint32_t flystick = 0;                          // its id in DTrack's 6df2 lines
  double speed = defaults::kNavigationSpeed;           // m/s at a full joystick
  double turn_speed = defaults::kNavigationTurnSpeed;  // degrees/s at a full joystick
  std::uint32_t reset_button = defaults::kNavigationResetButton;
  double dead_zone = defaults::kNavigationDeadZone;
  glm::dvec3 up{0.0, 1.0, 0.0};        // the world's vertical, installation axes (unit)
  glm::dvec3 pointer{0.0, 0.0, -1.0};  // the wand's direction in the flystick's frame (unit)

  friend bool operator==(const Navigation&, const Navigation&) = default;
};

// Checks `navigation` (at `path`) and types it, defaults applied: an unknown
// mode, a speed or turn speed that is not positive or beyond the most, a dead
// zone outside [0, kMostDeadZone], a reset button beyond a flystick's, up or
// pointer not unit. Whether a flystick mode has a DTrack to hear is the
// viewer's check (it knows the tracking).
[[nodiscard]] Navigation parse_navigation(const schema::Navigation& navigation, const std::string& path,
                                          std::vector<Problem>& problems);

}  // namespace optique::config
