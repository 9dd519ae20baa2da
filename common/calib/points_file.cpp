#include "calib/points_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "calib/screen_frame.h"
#include "util/join.h"
#include "util/read_file.h"

namespace optique::calib {
namespace {

using nlohmann::json;

std::string type_of(const json& value) {
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_array()) return fmt::format("an array of {}", value.size());
  if (value.is_object()) return "an object";
  if (value.is_boolean()) return "true/false";
  return "null";
}

// `count` finite numbers at `value`, or an error naming `field`.
template <std::size_t N>
Result<std::array<double, N>> numbers(const json& value, const std::string& field) {
  if (!value.is_array() || value.size() != N) {
    return Error{fmt::format("{}: needs {} numbers (got {})", field, N, type_of(value))};
  }
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) {
    const json& v = value[i];
    if (!v.is_number()) return Error{fmt::format("{}[{}]: needs a number (got {})", field, i, type_of(v))};
    out[i] = v.get<double>();
    if (!std::isfinite(out[i])) return Error{fmt::format("{}[{}]: not a finite number", field, i)};
  }
  return out;
}

Result<int> positive_integer(const json& object, const std::string& key, const std::string& field) {
  const auto found = object.find(key);
  if (found == object.end()) return Error{fmt::format("{}: missing (the projector's image size in pixels)", field)};
  if (!found->is_number_integer() || found->get<std::int64_t>() <= 0 || found->get<std::int64_t>() > (1 << 20)) {
    return Error{fmt::format("{}: needs a positive whole number of pixels (got {})", field, found->dump())};
  }
  return static_cast<int>(found->get<std::int64_t>());
}

Result<void> only_keys(const json& object, std::initializer_list<const char*> allowed, const std::string& field) {
  for (const auto& item : object.items()) {
    // Not a structured binding: clang 14 (the sanitizer build) cannot capture one.
    const std::string& key = item.key();
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
      const std::string names = util::joined(allowed, [](const char* a) { return fmt::format("\"{}\"", a); });
      return Error{
          fmt::format("{}: unknown field \"{}\" (expected {})", field.empty() ? "top level" : field, key, names)};
    }
  }
  return {};
}

// 1-based line and column of byte offset `byte` (nlohmann counts the bytes read,
// so the offending character is the last of them).
std::pair<std::size_t, std::size_t> line_column(std::string_view text, std::size_t byte) {
  const std::size_t end = std::min(byte == 0 ? 0 : byte - 1, text.size());
  std::size_t line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return {line, end - line_start + 1};
}

Result<PointsFile> parse_document(const json& document) {
  if (!document.is_object())
    return Error{fmt::format("needs a JSON object at the top level (got {})", type_of(document))};
  if (auto ok = only_keys(document, {"projector", "points", "tracker_to_screen"}, ""); !ok) return Error{ok.error()};
  PointsFile file;

  const auto projector = document.find("projector");
  if (projector == document.end() || !projector->is_object()) {
    return Error{"projector: needs {\"width\": W, \"height\": H} (the image size in pixels)"};
  }
  if (auto ok = only_keys(*projector, {"width", "height"}, "projector"); !ok) return Error{ok.error()};
  auto width = positive_integer(*projector, "width", "projector.width");
  if (!width) return Error{width.error()};
  auto height = positive_integer(*projector, "height", "projector.height");
  if (!height) return Error{height.error()};
  file.projector = {width.value(), height.value()};

  const auto points = document.find("points");
  if (points == document.end() || !points->is_array()) {
    return Error{"points: needs an array of {\"pixel\": [x, y], \"screen\": [X, Y]} (or \"tracker\": [X, Y, Z])"};
  }
  for (std::size_t i = 0; i < points->size(); ++i) {
    const json& point = (*points)[i];
    const std::string field = fmt::format("points[{}]", i);
    if (!point.is_object()) return Error{fmt::format("{}: needs an object (got {})", field, type_of(point))};
    if (auto ok = only_keys(point, {"pixel", "screen", "tracker"}, field); !ok) return Error{ok.error()};
    const auto pixel = point.find("pixel");
    if (pixel == point.end()) return Error{field + ".pixel: missing"};
    auto xy = numbers<2>(*pixel, field + ".pixel");
    if (!xy) return Error{xy.error()};
    const glm::dvec2 p(xy.value()[0], xy.value()[1]);
    if (p.x < 0.0 || p.y < 0.0 || p.x > file.projector.width || p.y > file.projector.height) {
      file.warnings.push_back(fmt::format("{}.pixel ({:g}, {:g}) is outside the {}×{} image", field, p.x, p.y,
                                          file.projector.width, file.projector.height));
    }
    file.pixels.push_back(p);

    const bool has_screen = point.contains("screen");
    const bool has_tracker = point.contains("tracker");
    if (has_screen == has_tracker) {
      return Error{
          fmt::format("{}: needs exactly one of \"screen\": [X, Y] (metres on the screen) or \"tracker\": "
                      "[X, Y, Z] (a tracker reading){}",
                      field, has_screen ? " (it has both)" : "")};
    }
    const PointKind kind = has_screen ? PointKind::kScreen : PointKind::kTracker;
    if (i == 0) file.kind = kind;
    if (kind != file.kind) {
      return Error{fmt::format("{}: has \"{}\" but points[0] has \"{}\": all points must be of one kind", field,
                               has_screen ? "screen" : "tracker", has_screen ? "tracker" : "screen")};
    }
    if (has_screen) {
      auto s = numbers<2>(point["screen"], field + ".screen");
      if (!s) return Error{s.error()};
      file.screen.emplace_back(s.value()[0], s.value()[1]);
    } else {
      auto t = numbers<3>(point["tracker"], field + ".tracker");
      if (!t) return Error{t.error()};
      file.tracker.emplace_back(t.value()[0], t.value()[1], t.value()[2]);
    }
  }

  if (const auto frame = document.find("tracker_to_screen"); frame != document.end()) {
    if (file.kind != PointKind::kTracker || points->empty()) {
      return Error{"tracker_to_screen: only goes with \"tracker\" points (it maps their readings to the screen)"};
    }
    auto values = numbers<16>(*frame, "tracker_to_screen");
    if (!values) return Error{values.error() + " (a 4×4 matrix, row-major)"};
    glm::dmat4 m(1.0);
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) m[c][r] = values.value()[static_cast<std::size_t>(4 * r + c)];
    }
    if (auto rigid = check_rigid(m); !rigid) return Error{"tracker_to_screen: " + rigid.error()};
    file.tracker_to_screen = m;
  }
  return file;
}

}  // namespace

Result<PointsFile> parse_points_file(std::string_view text, const std::string& name) {
  json document;
  try {
    document = json::parse(text);
  } catch (const json::parse_error& e) {
    const auto [line, column] = line_column(text, e.byte);
    // nlohmann's own text, less its "[json.exception...] parse error at ...: " prefix.
    std::string what = e.what();
    if (const auto colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
    return Error{fmt::format("{}:{}:{}: not valid JSON: {}", name, line, column, what)};
  } catch (const json::out_of_range& e) {
    // A number too large for a double ("number overflow parsing '1e999'"): no
    // position comes with it, so find the literal it names.
    std::string what = e.what();
    if (const auto colon = what.find("] "); colon != std::string::npos) what = what.substr(colon + 2);
    const auto open = what.find('\'');
    const auto close = what.rfind('\'');
    if (open != std::string::npos && close > open) {
      if (const auto at = text.find(what.substr(open + 1, close - open - 1)); at != std::string_view::npos) {
        const auto [line, column] = line_column(text, at + 1);
        return Error{fmt::format("{}:{}:{}: not valid JSON: {}", name, line, column, what)};
      }
    }
    return Error{fmt::format("{}: not valid JSON: {}", name, what)};
  }
  auto file = parse_document(document);
  if (!file) return Error{name + ": " + file.error()};
  return file;
}

Result<PointsFile> read_points_file(const std::string& path) {
  auto text = util::read_file(path, "points file");
  if (!text) return Error{text.error()};
  return parse_points_file(text.value(), path);
}

}  // namespace optique::calib
