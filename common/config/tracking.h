#pragma once
// A tracked head, checked and typed (`viewer.tracking`): where its samples come
// from, how the tracker's space sits in the world, where the eyes are on the
// tracked body, how the master predicts the head at each frame's display time,
// and what it does when the tracker goes quiet.

#include <chrono>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "config/problem.h"
#include "optique/config.pb.h"

namespace optique::config {

// dtrack: ART DTrack's ASCII output over UDP; replay: a CSV of time, position and
// orientation, looped (demos, tests).
enum class TrackingSource { dtrack, replay };
// none: the last sample as it is; constant-velocity: moved on at its velocity;
// double-exponential: LaViola's double exponential smoothing predictor (2003).
enum class HeadPrediction { none, constant_velocity, double_exponential };

[[nodiscard]] std::string_view to_string(TrackingSource source);
[[nodiscard]] std::string_view to_string(HeadPrediction prediction);

inline constexpr std::uint16_t kDefaultTrackingPort = 5000;  // DTrack's usual output port
inline constexpr double kDefaultSmoothing = 0.7;  // measured best with a tracker's jitter (docs/bench/tracking.md)
inline constexpr double kMostTrackingLatencyMs = 500.0;

struct Tracking {
  TrackingSource source = TrackingSource::dtrack;
  std::string listen = "127.0.0.1";  // dtrack; another address only with `from`
  std::string from;                // dtrack: the tracker's address, datagrams from others ignored; empty: any
  std::uint16_t port = kDefaultTrackingPort;
  std::string file;        // replay: resolved against the config file's folder when parsed
  std::uint32_t body = 0;  // dtrack: the body's id in DTrack's output
  // Tracker space → world: p_world = tracker_axes · p_tracker + tracker_origin
  // (metres; DTrack's millimetres are converted when parsed).
  glm::dvec3 tracker_origin{0.0};
  glm::dmat3 tracker_axes{1.0};  // columns: the tracker's x, y and z in the world
  glm::dvec3 eye_offset{0.0};    // tracked body → the eyes' centre, in the body's frame
  HeadPrediction prediction = HeadPrediction::double_exponential;
  double smoothing = kDefaultSmoothing;  // double-exponential's alpha
  // From the tracker's exposure to the sample's arrival at the master: a sample
  // shows the head as it was this long before it arrived.
  std::chrono::microseconds latency{0};
  std::chrono::milliseconds lost_after{200};  // no sample this long: lost
  std::chrono::milliseconds hold{1000};       // then the last pose, held
  std::chrono::milliseconds ease{2000};       // then eased to the viewer's eye/path

  friend bool operator==(const Tracking&, const Tracking&) = default;
};

// Checks `tracking` (at `path` in the file) and types it, defaults applied.
// Every problem goes to `problems`, each with its own message: an unknown source
// or prediction, a replay without its file (or a file for dtrack), an address
// that is not one, tracker axes that are not unit, at right angles and right-
// handed, an eye offset of a metre or more, a smoothing outside (0, 1), a
// latency beyond kMostTrackingLatencyMs, a dtrack source that listens beyond
// loopback without `from`.
[[nodiscard]] Tracking parse_tracking(const schema::Tracking& tracking, const std::string& path,
                                      std::vector<Problem>& problems);

}  // namespace optique::config
