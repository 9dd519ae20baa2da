#pragma once
// A head walking in front of a wall, for the tracking test and bench: 1.2 m/s
// around a circle of 2 m radius centred 3 m from the wall, the eyes bobbing
// 1 cm at 1.8 Hz (a step's rhythm), the head facing where it walks. Peak
// acceleration about 1.5 m/s² (0.72 turning, 1.28 bobbing).

#include <cmath>
#include <cstdio>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

namespace optique::testing {

struct HeadWalk {
  static constexpr double kSpeed = 1.2;   // m/s
  static constexpr double kRadius = 2.0;  // m
  static glm::dvec3 eyes(double t) {
    const double a = kSpeed / kRadius * t;
    return {kRadius * std::sin(a), 1.6 + 0.01 * std::sin(2.0 * M_PI * 1.8 * t), 3.0 + kRadius * std::cos(a)};
  }
  static glm::dquat head(double t) { return glm::angleAxis(kSpeed / kRadius * t, glm::dvec3(0.0, 1.0, 0.0)); }
};

// Body `id` as DTrack writes it in a 6d line: millimetres, the matrix column by
// column.
inline std::string dtrack_body(unsigned id, const glm::dvec3& position, const glm::dquat& turn) {
  const glm::dmat3 r = glm::mat3_cast(turn);
  char text[400];
  std::snprintf(text, sizeof text, "[%u 1.000][%.3f %.3f %.3f][%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f]", id,
                position.x * 1000.0, position.y * 1000.0, position.z * 1000.0, r[0][0], r[0][1], r[0][2], r[1][0],
                r[1][1], r[1][2], r[2][0], r[2][1], r[2][2]);
  return text;
}

// Flystick `id` as DTrack writes it in a 6df2 line (6 buttons, a joystick):
// its pose, the buttons down as bits, the joystick's x and y.
inline std::string dtrack_flystick(unsigned id, const glm::dvec3& position, const glm::dquat& turn, unsigned buttons,
                                   double x, double y) {
  const glm::dmat3 r = glm::mat3_cast(turn);
  char text[400];
  std::snprintf(text, sizeof text,
                "[%u 1.000 6 2][%.3f %.3f %.3f][%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f][%u %.3f %.3f]", id,
                position.x * 1000.0, position.y * 1000.0, position.z * 1000.0, r[0][0], r[0][1], r[0][2], r[1][0],
                r[1][1], r[1][2], r[2][0], r[2][1], r[2][2], buttons, x, y);
  return text;
}

// One DTrack frame: its counter, ts2 with the tracker's latency, and the body.
inline std::string dtrack_frame(unsigned long long frame, double latency_seconds, const std::string& body) {
  return "fr " + std::to_string(frame) + "\r\nts2 0 0 " + std::to_string(std::lround(latency_seconds * 1e6)) +
         "\r\n6d 1 " + body + "\r\n";
}

}  // namespace optique::testing
