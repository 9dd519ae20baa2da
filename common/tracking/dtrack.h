#pragma once
// ART DTrack's ASCII output (one UDP datagram per tracker frame), parsed without
// IO: the frame counter (`fr`), the timestamp (`ts`, or `ts2` with the tracker's
// own latency), the standard 6DOF bodies (`6d`) and the flysticks (`6df2`:
// a body with buttons and a joystick). Other lines (markers, hands, ...) are
// skipped, as DTrack's own SDK skips what it does not know. Anything malformed is refused with the line and what is
// wrong: the datagram is then ignored as a whole. So is one without any line DTrack writes every frame (fr, ts, ts2,
// 6dcal, 6d), or with bytes that are not printable ASCII.
//
// A `6d` line: `6d <count> [<id> <quality>][<x> <y> <z> (<η> <θ> <φ>)][<b0> … <b8>] …`,
// position in millimetres, the rotation matrix column by column (b0 b1 b2 the
// body's x axis in tracker space).
// A `6df2` line: `6df2 <defined> <count> [<id> <quality> <buttons> <controllers>]
// [<x> <y> <z>][<b0> … <b8>][<button words> … <controller values> …] …`: the
// buttons as bits, 32 to a word (⌈buttons / 32⌉ words), then each controller
// (a joystick's axes) in −1…1. A flystick the cameras do not see has quality
// −1 and zeros for its pose (taken as the origin, unturned); its buttons and
// joystick still count.

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "util/result.h"

namespace optique::tracking {

// Datagrams longer than this are refused unread (a DTrack frame with every
// kind of output is a few kilobytes).
inline constexpr std::size_t kMaxDTrackDatagram = 65507;
inline constexpr std::uint32_t kMaxDTrackBodies = 256;
// Farther than this from the tracker's origin (mm, the distance, not per axis) is
// no room's tracking; a latency beyond this (s) no tracker's.
inline constexpr double kMostDTrackPosition = 100'000.0;
inline constexpr double kMostDTrackLatency = 1.0;

struct DTrackBody {
  std::uint32_t id = 0;
  double quality = 0.0;      // 0…1; DTrack lists only the bodies it tracks
  glm::dvec3 position{0.0};  // millimetres, tracker space
  glm::dmat3 rotation{1.0};  // body → tracker space; checked to be a rotation
};

// At most this many buttons and controllers a flystick (a Flystick 2 has 6
// and 2; the format allows more).
inline constexpr std::uint32_t kMaxFlystickButtons = 64;
inline constexpr std::uint32_t kMaxFlystickControllers = 16;

struct DTrackFlystick {
  DTrackBody body;                  // quality −1: not seen, and no pose
  std::vector<bool> buttons;        // pressed, by index
  std::vector<double> controllers;  // −1…1: a joystick's x is [0], y [1]
};

struct DTrackFrame {
  std::optional<std::uint64_t> frame;  // fr
  std::optional<double> timestamp;     // seconds (ts, or ts2's seconds and microseconds)
  std::optional<double> latency;       // seconds from exposure to output (ts2)
  std::vector<DTrackBody> bodies;
  std::vector<DTrackFlystick> flysticks;  // 6df2
};

[[nodiscard]] Result<DTrackFrame> parse_dtrack(std::string_view datagram);

}  // namespace optique::tracking
