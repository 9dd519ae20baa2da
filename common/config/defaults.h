#pragma once
// The value each setting takes when the installation leaves it at zero or empty:
// one place, read by apply_defaults and by the checks that relate two settings.

#include <cstdint>

namespace optique::config::defaults {

inline constexpr double kFrameRate = 60.0;
inline constexpr std::uint32_t kFrameTimeoutMs = 500;
inline constexpr std::uint32_t kStartupTimeoutMs = 10000;
inline constexpr std::uint32_t kHandshakeTimeoutMs = 2000;
inline constexpr std::uint32_t kHeartbeatMs = 250;
inline constexpr std::uint32_t kMinLivenessTimeoutMs = 3000;  // or 3 heartbeats, if longer
inline constexpr std::uint32_t kPresentLeadUs = 2000;
inline constexpr std::uint32_t kMaxMessageBytes = 16u << 20;
inline constexpr std::uint32_t kMaxPendingConnections = 16;
inline constexpr std::uint16_t kStatusPort = 7480;
inline constexpr std::uint32_t kStatusMaxConnections = 256;
inline constexpr std::uint16_t kApiPort = 7490;
inline constexpr std::uint32_t kApiMaxSessions = 16;
inline constexpr std::uint32_t kApiMaxEditsPerFrame = 100000;
inline constexpr std::uint32_t kApiMaxInstances = 100000;
inline constexpr double kEyeSeparation = 0.065;
inline constexpr double kNear = 0.05;
inline constexpr double kFar = 100.0;
inline constexpr double kPixelsPerMetre = 200.0;
inline constexpr double kNavigationSpeed = 1.5;       // m/s: a brisk walk
inline constexpr double kNavigationTurnSpeed = 45.0;  // degrees/s
inline constexpr std::uint32_t kNavigationResetButton = 1;
inline constexpr double kNavigationDeadZone = 0.1;
inline constexpr double kBlurRadius = 8.0;  // a defocus projector's, screen pixels

}  // namespace optique::config::defaults
