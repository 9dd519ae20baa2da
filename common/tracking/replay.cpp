#include "tracking/replay.h"

#include <charconv>
#include <cmath>

#include "util/read_file.h"

namespace optique::tracking {
namespace {

constexpr int kColumns = 8;
constexpr const char* kNames[kColumns] = {"time", "x", "y", "z", "qw", "qx", "qy", "qz"};

// The row's fields, split at commas and trimmed.
std::vector<std::string_view> fields_of(std::string_view line) {
  std::vector<std::string_view> fields;
  while (true) {
    const std::size_t comma = line.find(',');
    std::string_view field = line.substr(0, comma);
    while (!field.empty() && (field.front() == ' ' || field.front() == '\t')) field.remove_prefix(1);
    while (!field.empty() && (field.back() == ' ' || field.back() == '\t')) field.remove_suffix(1);
    fields.push_back(field);
    if (comma == std::string_view::npos) break;
    line.remove_prefix(comma + 1);
  }
  return fields;
}

bool parse_number(std::string_view field, double& out) {
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), out);
  return error == std::errc() && end == field.data() + field.size() && !field.empty();
}

}  // namespace

Result<std::vector<ReplaySample>> parse_replay(std::string_view text, const std::string& name) {
  std::vector<ReplaySample> samples;
  std::size_t line_number = 0;
  bool first_row = true;
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.find_first_not_of(" \t") == std::string_view::npos || line.front() == '#') continue;
    const std::string where = name + ":" + std::to_string(line_number);
    const std::vector<std::string_view> fields = fields_of(line);
    double first = 0.0;
    if (first_row && !parse_number(fields.front(), first)) {
      first_row = false;  // a header
      continue;
    }
    first_row = false;
    if (fields.size() != kColumns) {
      return Error{where + ": " + std::to_string(fields.size()) + " fields; a row is time, x, y, z, qw, qx, qy, qz"};
    }
    double v[kColumns];
    for (int i = 0; i < kColumns; ++i) {
      if (!parse_number(fields[static_cast<std::size_t>(i)], v[i]) || !std::isfinite(v[i])) {
        return Error{where + ": " + kNames[i] + " is not a finite number ('" +
                     std::string(fields[static_cast<std::size_t>(i)].substr(0, 24)) + "')"};
      }
    }
    ReplaySample s;
    s.time = v[0];
    s.position = {v[1], v[2], v[3]};
    const glm::dquat q(v[4], v[5], v[6], v[7]);
    const double norm = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (std::abs(norm - 1.0) > 1e-3) {
      return Error{where + ": qw, qx, qy, qz is not a unit quaternion (norm " + std::to_string(norm) + ")"};
    }
    s.orientation = q / norm;
    if (s.time < 0.0) return Error{where + ": time must be 0 or more (got " + std::to_string(s.time) + ")"};
    if (!samples.empty() && !(s.time >= samples.back().time + 0.001)) {
      return Error{where + ": times must increase by 1 ms at least (" + std::to_string(s.time) + " after " +
                   std::to_string(samples.back().time) + ")"};
    }
    if (samples.size() >= kMostReplaySamples) {
      return Error{name + ": more than " + std::to_string(kMostReplaySamples) + " samples"};
    }
    samples.push_back(s);
  }
  if (samples.empty()) return Error{name + ": no samples (rows of time, x, y, z, qw, qx, qy, qz)"};
  return samples;
}

Result<std::vector<ReplaySample>> load_replay(const std::string& path) {
  auto text = util::read_file(path, "tracking replay");
  if (!text) return Error{text.error()};
  return parse_replay(text.value(), path);
}

}  // namespace optique::tracking
