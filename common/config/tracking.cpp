#include "config/tracking.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "config/address.h"
#include "util/number_text.h"

namespace optique::config {

using util::number_text;

std::string_view to_string(TrackingSource source) { return source == TrackingSource::dtrack ? "dtrack" : "replay"; }

std::string_view to_string(HeadPrediction prediction) {
  switch (prediction) {
    case HeadPrediction::none:
      return "none";
    case HeadPrediction::constant_velocity:
      return "constant-velocity";
    case HeadPrediction::double_exponential:
      break;
  }
  return "double-exponential";
}

namespace {

// A 3-vector at `path`, or a problem; `fallback` where it is absent.
glm::dvec3 vector_at(const google::protobuf::RepeatedField<double>& v, const std::string& path, glm::dvec3 fallback,
                     std::vector<Problem>& problems) {
  if (v.empty()) return fallback;
  if (v.size() != 3) {
    problems.push_back({path, "must be [x, y, z] (got " + std::to_string(v.size()) + " numbers)"});
    return fallback;
  }
  const glm::dvec3 out{v[0], v[1], v[2]};
  if (!std::isfinite(out.x) || !std::isfinite(out.y) || !std::isfinite(out.z)) {
    problems.push_back({path, "must be finite"});
    return fallback;
  }
  return out;
}

// The tracker's axes as the world sees them: unit, at right angles,
// right-handed (a rotation, so that an orientation stays one).
glm::dmat3 axes_at(const schema::TrackerAxes& axes, const std::string& path, std::vector<Problem>& problems) {
  constexpr double kTolerance = 1e-3;
  const std::size_t before = problems.size();
  const glm::dvec3 x = vector_at(axes.x(), path + ".x", {1.0, 0.0, 0.0}, problems);
  const glm::dvec3 y = vector_at(axes.y(), path + ".y", {0.0, 1.0, 0.0}, problems);
  const glm::dvec3 z = vector_at(axes.z(), path + ".z", {0.0, 0.0, 1.0}, problems);
  if (problems.size() != before) return glm::dmat3(1.0);
  const char* names[] = {"x", "y", "z"};
  const glm::dvec3 columns[] = {x, y, z};
  bool unit = true;
  for (int i = 0; i < 3; ++i) {
    const double length = glm::length(columns[i]);
    if (std::abs(length - 1.0) > kTolerance) {
      problems.push_back({path + "." + names[i], "must be a unit vector (length " + number_text(length) + ")"});
      unit = false;
    }
  }
  if (!unit) return glm::dmat3(1.0);
  if (std::abs(glm::dot(x, y)) > kTolerance || std::abs(glm::dot(y, z)) > kTolerance ||
      std::abs(glm::dot(z, x)) > kTolerance) {
    problems.push_back({path, "x, y and z must be at right angles"});
    return glm::dmat3(1.0);
  }
  if (glm::dot(glm::cross(x, y), z) < 0.0) {
    problems.push_back(
        {path, "must be right-handed (x × y = z): a mirrored tracker space turns the head the wrong way"});
    return glm::dmat3(1.0);
  }
  return glm::dmat3(x, y, z);
}

}  // namespace

Tracking parse_tracking(const schema::Tracking& t, const std::string& path, std::vector<Problem>& problems) {
  Tracking out;
  if (t.source() == "dtrack") {
    out.source = TrackingSource::dtrack;
  } else if (t.source() == "replay") {
    out.source = TrackingSource::replay;
  } else {
    problems.push_back({path + ".source", t.source().empty() ? "is required: dtrack or replay"
                                                             : "must be dtrack or replay (got '" + t.source() + "')"});
  }
  if (!t.listen().empty()) {
    if (!is_ip_address(t.listen())) {
      problems.push_back({path + ".listen", "'" + t.listen() + "' is not an IPv4 or IPv6 address"});
    } else {
      out.listen = t.listen();
    }
  }
  if (!t.from().empty()) {
    if (!is_ip_address(t.from())) {
      problems.push_back({path + ".from", "'" + t.from() + "' is not an IPv4 or IPv6 address (the tracker's)"});
    } else {
      out.from = canonical_address(t.from());  // as senders are written (net::read_datagram_stamped)
    }
  }
  // Anyone who reaches the port can steer the head: beyond this machine, only the tracker may.
  if (out.source == TrackingSource::dtrack && t.from().empty() && !is_loopback_address(out.listen)) {
    problems.push_back({path + ".from", "is required when listen is " + out.listen +
                                            " (not loopback): the tracker's address, so that no other host on the "
                                            "network can steer the head"});
  }
  if (t.port() > 65535) {
    problems.push_back({path + ".port", "must be 1..65535, or 0 for " + std::to_string(kDefaultTrackingPort) +
                                            " (got " + std::to_string(t.port()) + ")"});
  } else if (t.port() != 0) {
    out.port = static_cast<std::uint16_t>(t.port());
  }
  out.file = t.file();
  if (out.source == TrackingSource::replay && out.file.empty()) {
    problems.push_back({path + ".file", "is required with source replay: a CSV of time, x, y, z, qw, qx, qy, qz"});
  }
  if (t.source() == "dtrack" && !out.file.empty()) {
    problems.push_back({path + ".file", "is for source replay; dtrack receives its samples on listen:port"});
  }
  out.body = t.body();
  out.tracker_origin = vector_at(t.tracker_origin(), path + ".tracker_origin", glm::dvec3(0.0), problems);
  if (t.has_tracker_axes()) out.tracker_axes = axes_at(t.tracker_axes(), path + ".tracker_axes", problems);
  out.eye_offset = vector_at(t.eye_offset(), path + ".eye_offset", glm::dvec3(0.0), problems);
  if (glm::length(out.eye_offset) >= 1.0) {
    problems.push_back({path + ".eye_offset", "is in metres, in the tracked body's frame; " +
                                                  number_text(glm::length(out.eye_offset)) +
                                                  " m from the body to the eyes is not a head"});
  }
  if (t.prediction().empty() || t.prediction() == "double-exponential") {
    out.prediction = HeadPrediction::double_exponential;
  } else if (t.prediction() == "constant-velocity") {
    out.prediction = HeadPrediction::constant_velocity;
  } else if (t.prediction() == "none") {
    out.prediction = HeadPrediction::none;
  } else {
    problems.push_back(
        {path + ".prediction", "must be none, constant-velocity or double-exponential (got '" + t.prediction() + "')"});
  }
  if (t.smoothing() != 0.0) {
    if (!(t.smoothing() > 0.0 && t.smoothing() < 1.0)) {
      problems.push_back({path + ".smoothing", "must be in (0, 1), or 0 for " + number_text(kDefaultSmoothing) +
                                                   " (got " + number_text(t.smoothing()) + ")"});
    } else {
      out.smoothing = t.smoothing();
    }
  }
  if (!(t.latency_ms() >= 0.0 && t.latency_ms() <= kMostTrackingLatencyMs)) {
    problems.push_back({path + ".latency_ms", "must be 0…" + number_text(kMostTrackingLatencyMs) + " ms (got " +
                                                  number_text(t.latency_ms()) + ")"});
  } else {
    out.latency = std::chrono::microseconds(static_cast<std::int64_t>(std::llround(t.latency_ms() * 1000.0)));
  }
  // Zero: the default (Tracking's own).
  if (t.lost_after_ms() != 0) out.lost_after = std::chrono::milliseconds(t.lost_after_ms());
  if (t.hold_ms() != 0) out.hold = std::chrono::milliseconds(t.hold_ms());
  if (t.ease_ms() != 0) out.ease = std::chrono::milliseconds(t.ease_ms());
  return out;
}

}  // namespace optique::config
