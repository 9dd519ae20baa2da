#pragma once
// What every section of the installation's check needs: it collects problems
// (each with its field path) and turns the file's numbers, vectors and names
// into typed values in the same step, so that a section is checked and built
// in one pass. Where a value is wrong it says so and gives nothing (or the
// default), and the build goes on, so that every problem is found at once.

#include <array>
#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "config/names.h"
#include "config/problem.h"
#include "optique/config.pb.h"
#include "util/join.h"

namespace optique::config {

class Checker {
 public:
  explicit Checker(std::vector<Problem>& problems) : problems_(problems) {}

  void fail(const std::string& path, const std::string& message) { problems_.push_back({path, message}); }
  // For the section parsers that take the list itself (colour fields, tracking).
  [[nodiscard]] std::vector<Problem>& problems() { return problems_; }
  [[nodiscard]] std::size_t count() const { return problems_.size(); }

  bool finite(const std::string& path, double v);
  void positive(const std::string& path, double v);
  void non_negative(const std::string& path, double v);
  // `time` after `previous` (a path's points): "times must increase".
  void later(const std::string& path, double time, double previous);

  // [x, y, z] of finite numbers.
  std::optional<glm::dvec3> vec3(const std::string& path, const google::protobuf::RepeatedField<double>& v);
  // A vector of length 1 (within 1e-3).
  bool unit(const std::string& path, const glm::dvec3& v);

  // An id that is there, unique among `seen` and usable as a folder name.
  void id(const std::string& path, const std::string& id, std::set<std::string>& seen, const char* what);

  // A name of `table` (config/names.h); empty: the default.
  template <class E, std::size_t N>
  std::optional<E> name(const std::string& path, const std::string& value, const std::array<Named<E>, N>& table) {
    const std::optional<E> parsed = from_name(table, value);
    if (!parsed) fail(path, "unknown value '" + value + "' (expected one of: " + util::joined(names_of(table)) + ")");
    return parsed;
  }

 private:
  std::vector<Problem>& problems_;
};

}  // namespace optique::config
