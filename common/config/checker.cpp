#include "config/checker.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "util/id_text.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

bool usable_as_file_name(const std::string& id) {
  if (id.empty() || id == "." || id == "..") return false;
  return std::all_of(id.begin(), id.end(), util::is_id_char);
}

}  // namespace

bool Checker::finite(const std::string& path, double v) {
  if (std::isfinite(v)) return true;
  fail(path, "must be a finite number (got " + number_text(v) + ")");
  return false;
}

void Checker::positive(const std::string& path, double v) {
  if (finite(path, v) && v <= 0.0) fail(path, "must be > 0 (got " + number_text(v) + ")");
}

void Checker::non_negative(const std::string& path, double v) {
  if (finite(path, v) && v < 0.0) fail(path, "must be >= 0 (got " + number_text(v) + ")");
}

void Checker::later(const std::string& path, double time, double previous) {
  if (!(time > previous)) {
    fail(path, "times must increase (" + number_text(time) + " after " + number_text(previous) + ")");
  }
}

std::optional<glm::dvec3> Checker::vec3(const std::string& path, const google::protobuf::RepeatedField<double>& v) {
  if (v.size() != 3) {
    fail(path, "must be [x, y, z] (got " + std::to_string(v.size()) + " numbers)");
    return std::nullopt;
  }
  bool ok = true;
  for (int i = 0; i < 3; ++i) ok = finite(path + "[" + std::to_string(i) + "]", v[i]) && ok;
  if (!ok) return std::nullopt;
  return glm::dvec3(v[0], v[1], v[2]);
}

bool Checker::unit(const std::string& path, const glm::dvec3& v) {
  constexpr double kTolerance = 1e-3;
  if (std::abs(glm::length(v) - 1.0) <= kTolerance) return true;
  fail(path, "must be a unit vector (length " + number_text(glm::length(v)) + ")");
  return false;
}

void Checker::id(const std::string& path, const std::string& id, std::set<std::string>& seen, const char* what) {
  if (id.empty()) {
    fail(path, std::string("every ") + what + " needs an id");
  } else if (!usable_as_file_name(id)) {
    fail(path, "id '" + id + "' may only use letters, digits, '-', '_' and '.' (it names output folders)");
  } else if (!seen.insert(id).second) {
    fail(path, std::string("duplicate ") + what + " id '" + id + "'");
  }
}

}  // namespace optique::config
