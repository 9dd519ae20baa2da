#include "tracking/dtrack.h"

#include <charconv>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace optique::tracking {
namespace {

// Reads one line's tokens: numbers, and the brackets around a body's blocks.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}

  void skip_spaces() {
    while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\t')) ++at_;
  }
  [[nodiscard]] bool done() {
    skip_spaces();
    return at_ >= text_.size();
  }
  [[nodiscard]] bool expect(char c) {
    skip_spaces();
    if (at_ >= text_.size() || text_[at_] != c) return false;
    ++at_;
    return true;
  }
  [[nodiscard]] bool peek(char c) {
    skip_spaces();
    return at_ < text_.size() && text_[at_] == c;
  }
  template <class T>
  [[nodiscard]] bool number(T& out) {
    skip_spaces();
    const char* begin = text_.data() + at_;
    const char* end = text_.data() + text_.size();
    const auto [stop, error] = std::from_chars(begin, end, out);
    if (error != std::errc() || stop == begin) return false;
    at_ += static_cast<std::size_t>(stop - begin);
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(out)) return false;
    }
    return true;
  }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
};

// Orthonormal and turning, not mirroring: DTrack prints six decimals.
bool is_rotation(const glm::dmat3& r) {
  constexpr double kTolerance = 1e-3;
  const glm::dmat3 product = glm::transpose(r) * r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (std::abs(product[i][j] - (i == j ? 1.0 : 0.0)) > kTolerance) return false;
    }
  }
  return glm::determinant(r) > 0.0;
}

// A body's position and rotation blocks, `[x y z (η θ φ)][b0 … b8]`, checked.
// `unseen_is_no_pose`: a quality below 0 says the cameras do not see it (a
// flystick's buttons still count), and DTrack writes zeros for its pose: read,
// not checked, and taken as the origin, unturned.
Result<void> parse_pose(Cursor& c, const std::string& which, DTrackBody& body, bool unseen_is_no_pose = false) {
  if (!c.expect('[') || !c.number(body.position.x) || !c.number(body.position.y) || !c.number(body.position.z)) {
    return Error{which + ": expected [x y z] in millimetres"};
  }
  // DTrack 1 also gives three angles; they say what the matrix says.
  if (!c.peek(']')) {
    double angle = 0.0;
    if (!c.number(angle) || !c.number(angle) || !c.number(angle)) return Error{which + ": expected [x y z η θ φ]"};
  }
  if (!c.expect(']') || !c.expect('[')) return Error{which + ": expected the rotation matrix after the position"};
  for (int i = 0; i < 9; ++i) {
    if (!c.number(body.rotation[i / 3][i % 3])) return Error{which + ": expected nine numbers of rotation matrix"};
  }
  if (!c.expect(']')) return Error{which + ": expected ] after the rotation matrix"};
  if (!(body.quality >= -1.0 && body.quality <= 1.0)) {
    return Error{which + ": quality " + std::to_string(body.quality) + " is outside -1…1"};
  }
  if (unseen_is_no_pose && body.quality < 0.0) {
    body.position = glm::dvec3(0.0);
    body.rotation = glm::dmat3(1.0);
    return {};
  }
  if (!is_rotation(body.rotation)) return Error{which + ": the rotation matrix is not a rotation"};
  if (!(glm::length(body.position) <= kMostDTrackPosition)) {
    return Error{which + ": a position more than " + std::to_string(static_cast<int>(kMostDTrackPosition / 1000)) +
                 " m from the tracker's origin"};
  }
  return {};
}

// How many `what` a line lists: at most kMaxDTrackBodies.
Result<std::uint32_t> listed(Cursor& c, const std::string& what) {
  std::uint32_t count = 0;
  if (!c.number(count)) return Error{"expected the number of " + what};
  if (count > kMaxDTrackBodies) {
    return Error{std::to_string(count) + " " + what + " (at most " + std::to_string(kMaxDTrackBodies) + ")"};
  }
  return count;
}

Result<std::vector<DTrackFlystick>> parse_6df2(Cursor& c) {
  std::uint32_t defined = 0;
  if (!c.number(defined)) return Error{"expected the number of flysticks defined"};
  auto listed_count = listed(c, "flysticks");
  if (!listed_count) return Error{listed_count.error()};
  const std::uint32_t count = listed_count.value();
  std::vector<DTrackFlystick> sticks;
  sticks.reserve(count);
  for (std::uint32_t s = 0; s < count; ++s) {
    const std::string which = "flystick " + std::to_string(s + 1) + " of " + std::to_string(count);
    DTrackFlystick stick;
    std::uint32_t buttons = 0;
    std::uint32_t controllers = 0;
    if (!c.expect('[') || !c.number(stick.body.id) || !c.number(stick.body.quality) || !c.number(buttons) ||
        !c.number(controllers) || !c.expect(']')) {
      return Error{which + ": expected [id quality buttons controllers]"};
    }
    if (buttons > kMaxFlystickButtons || controllers > kMaxFlystickControllers) {
      return Error{which + ": " + std::to_string(buttons) + " buttons and " + std::to_string(controllers) +
                   " controllers (at most " + std::to_string(kMaxFlystickButtons) + " and " +
                   std::to_string(kMaxFlystickControllers) + ")"};
    }
    if (auto pose = parse_pose(c, which, stick.body, true); !pose) return Error{pose.error()};
    if (!c.expect('[')) return Error{which + ": expected [buttons controllers] after the rotation matrix"};
    stick.buttons.resize(buttons);
    for (std::uint32_t word = 0; word < (buttons + 31) / 32; ++word) {
      std::uint32_t bits = 0;
      if (!c.number(bits))
        return Error{which + ": expected the buttons as " + std::to_string((buttons + 31) / 32) + " whole number(s)"};
      for (std::uint32_t b = 0; b < 32 && 32 * word + b < buttons; ++b)
        stick.buttons[32 * word + b] = ((bits >> b) & 1u) != 0;
    }
    stick.controllers.resize(controllers);
    for (double& value : stick.controllers) {
      if (!c.number(value) || value < -1.0 || value > 1.0) {
        return Error{which + ": expected " + std::to_string(controllers) + " controller values in -1…1"};
      }
    }
    if (!c.expect(']')) return Error{which + ": expected ] after the controllers"};
    sticks.push_back(std::move(stick));
  }
  if (!c.done()) return Error{"more after the " + std::to_string(count) + " flysticks"};
  return sticks;
}

Result<std::vector<DTrackBody>> parse_6d(Cursor& c) {
  auto listed_count = listed(c, "bodies");
  if (!listed_count) return Error{listed_count.error()};
  const std::uint32_t count = listed_count.value();
  std::vector<DTrackBody> bodies;
  bodies.reserve(count);
  for (std::uint32_t b = 0; b < count; ++b) {
    const std::string which = "body " + std::to_string(b + 1) + " of " + std::to_string(count);
    DTrackBody body;
    if (!c.expect('[') || !c.number(body.id) || !c.number(body.quality) || !c.expect(']')) {
      return Error{which + ": expected [id quality]"};
    }
    if (auto pose = parse_pose(c, which, body); !pose) return Error{pose.error()};
    bodies.push_back(body);
  }
  if (!c.done()) return Error{"more after the " + std::to_string(count) + " bodies"};
  return bodies;
}

}  // namespace

Result<DTrackFrame> parse_dtrack(std::string_view datagram) {
  if (datagram.size() > kMaxDTrackDatagram) return Error{"a datagram of " + std::to_string(datagram.size()) + " bytes"};
  DTrackFrame frame;
  bool bodies_seen = false;
  bool flysticks_seen = false;
  bool known_seen = false;  // a line DTrack writes in every frame
  std::size_t line_number = 0;
  while (!datagram.empty()) {
    const std::size_t end = datagram.find('\n');
    std::string_view line = datagram.substr(0, end);
    datagram = end == std::string_view::npos ? std::string_view{} : datagram.substr(end + 1);
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    for (char ch : line) {
      const auto byte = static_cast<unsigned char>(ch);
      if ((byte < 0x20 && ch != '\t') || byte >= 0x7f) {
        return Error{"line " + std::to_string(line_number) + ": a byte that is not printable ASCII"};
      }
    }
    const std::size_t space = line.find(' ');
    const std::string_view kind = line.substr(0, space);
    Cursor c(space == std::string_view::npos ? std::string_view{} : line.substr(space + 1));
    const auto wrong = [&](const std::string& what) {
      return Error{"line " + std::to_string(line_number) + " (" + std::string(kind.substr(0, 16)) + "): " + what};
    };
    known_seen = known_seen || kind == "fr" || kind == "ts" || kind == "ts2" || kind == "6d" || kind == "6dcal";
    if (kind == "fr") {
      std::uint64_t number = 0;
      if (!c.number(number) || !c.done()) return wrong("expected a frame counter");
      frame.frame = number;
    } else if (kind == "ts") {
      double seconds = 0.0;
      if (!c.number(seconds) || !c.done() || seconds < 0.0) return wrong("expected seconds since midnight");
      frame.timestamp = seconds;
    } else if (kind == "ts2") {
      std::uint64_t seconds = 0;
      std::uint32_t micro = 0;
      std::uint32_t latency = 0;
      if (!c.number(seconds) || !c.number(micro) || !c.number(latency) || !c.done() || micro >= 1000000) {
        return wrong("expected seconds, microseconds and the latency in microseconds");
      }
      frame.timestamp = static_cast<double>(seconds % (24 * 3600)) + micro * 1e-6;
      frame.latency = latency * 1e-6;
      if (*frame.latency > kMostDTrackLatency) return wrong("a latency of more than a second");
    } else if (kind == "6d") {
      if (bodies_seen) return wrong("a second 6d line");
      auto bodies = parse_6d(c);
      if (!bodies) return wrong(bodies.error());
      frame.bodies = std::move(bodies).value();
      bodies_seen = true;
    } else if (kind == "6df2") {
      if (flysticks_seen) return wrong("a second 6df2 line");
      auto sticks = parse_6df2(c);
      if (!sticks) return wrong(sticks.error());
      frame.flysticks = std::move(sticks).value();
      flysticks_seen = true;
    }
  }
  if (!known_seen) return Error{"no fr, ts or 6d line: not DTrack's ASCII output"};
  return frame;
}

}  // namespace optique::tracking
