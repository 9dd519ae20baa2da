#include "config/schema_check.h"
#include "util/join.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

namespace optique::config {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using Json = nlohmann::ordered_json;  // problems in the order of the file

// Edits (insert, delete, replace, swap two neighbours) from a to b: "widht" is
// one from "width".
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// The value as the file has it, shortened: for "(got …)".
std::string shown(const Json& value) {
  std::string text = value.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return text;
}

std::string kind_of(const Json& value) {
  if (value.is_string()) return "text " + shown(value);
  if (value.is_boolean()) return shown(value);
  if (value.is_number()) return "the number " + shown(value);
  if (value.is_array()) return "a list";
  if (value.is_object()) return "an object";
  return shown(value);
}

// As Protobuf's JSON parser: the field's own name or its lowerCamelCase JSON name.
const FieldDescriptor* by_name(const Descriptor& type, const std::string& key) {
  if (const FieldDescriptor* field = type.FindFieldByName(key)) return field;
  for (int i = 0; i < type.field_count(); ++i) {
    if (type.field(i)->json_name() == key) return type.field(i);
  }
  return nullptr;
}

std::string child(const std::string& path, const std::string& name) { return path.empty() ? name : path + "." + name; }

class SchemaChecker {
 public:
  explicit SchemaChecker(std::vector<Problem>& problems) : problems_(problems) {}

  void message(const Descriptor& type, const Json& object, const std::string& path) {
    if (!object.is_object()) {
      fail(path, "expected an object { … } (got " + kind_of(object) + ")");
      return;
    }
    for (const auto& [key, value] : object.items()) {
      const FieldDescriptor* field = by_name(type, key);
      if (field == nullptr) {
        unknown_field(type, key, child(path, key));
        continue;
      }
      if (value.is_null()) continue;  // the default, as Protobuf reads it
      const std::string at = child(path, key);
      if (field->is_repeated()) {
        if (!value.is_array()) {
          fail(at, "expected a list [ … ] (got " + kind_of(value) + ")");
          continue;
        }
        for (std::size_t i = 0; i < value.size(); ++i) one_value(*field, value[i], at + "[" + std::to_string(i) + "]");
      } else {
        one_value(*field, value, at);
      }
    }
  }

 private:
  void fail(const std::string& path, std::string message) {
    problems_.push_back({path.empty() ? "(the whole file)" : path, std::move(message)});
  }

  void unknown_field(const Descriptor& type, const std::string& key, const std::string& path) {
    std::string nearest;
    std::size_t best = std::numeric_limits<std::size_t>::max();
    std::string known;
    for (int i = 0; i < type.field_count(); ++i) {
      const std::string& name = type.field(i)->name();
      known += (known.empty() ? "" : ", ") + name;
      const std::size_t d = edit_distance(key, name);
      if (d < best) {
        best = d;
        nearest = name;
      }
    }
    if (best <= std::max<std::size_t>(2, key.size() / 3)) {
      fail(path, "no such field: did you mean '" + nearest + "'?");
    } else {
      fail(path, "no such field (fields here: " + known + ")");
    }
  }

  // `quoted_ok`: 64-bit fields, which Protobuf's own JSON writes in quotes (its
  // parser judges those); a 32-bit one in quotes ("640") is a slip worth a word.
  void integer(const Json& value, const std::string& path, double lowest, double highest, bool quoted_ok) {
    if (value.is_string()) {
      if (!quoted_ok) {
        fail(path, "expected a whole number, not text (got " + shown(value) + "; write it without quotes)");
      }
      return;
    }
    if (!value.is_number()) {
      fail(path, "expected a whole number (got " + kind_of(value) + ")");
      return;
    }
    const double v = value.get<double>();
    if (value.is_number_float() && std::floor(v) != v) {
      fail(path, "expected a whole number (got " + shown(value) + ")");
    } else if (v < lowest || v > highest) {
      const auto whole = [](double x) { return std::to_string(static_cast<long long>(x)); };
      if (lowest == 0.0 && v < 0.0) {
        fail(path, "must be 0 or more (got " + shown(value) + ")");
      } else {
        fail(path, "must be from " + whole(lowest) + " to " + whole(highest) + " (got " + shown(value) + ")");
      }
    }
  }

  void one_value(const FieldDescriptor& field, const Json& value, const std::string& path) {
    switch (field.cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        integer(value, path, std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max(), false);
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        integer(value, path, 0.0, std::numeric_limits<std::uint32_t>::max(), false);
        break;
      case FieldDescriptor::CPPTYPE_INT64:
        integer(value, path, -9.007199254740992e15, 9.007199254740992e15, true);
        break;
      case FieldDescriptor::CPPTYPE_UINT64:
        integer(value, path, 0.0, 9.007199254740992e15, true);
        break;
      case FieldDescriptor::CPPTYPE_DOUBLE:
      case FieldDescriptor::CPPTYPE_FLOAT:
        // Protobuf also reads "NaN" and "Infinity" as text: the validation
        // after it refuses those where they make no sense, by name.
        if (value.is_string()) {
          const std::string text = value.get<std::string>();
          if (text != "NaN" && text != "Infinity" && text != "-Infinity") {
            fail(path, "expected a number, not text (got " + shown(value) + "; write it without quotes)");
          }
        } else if (!value.is_number()) {
          fail(path, "expected a number (got " + kind_of(value) + ")");
        }
        break;
      case FieldDescriptor::CPPTYPE_BOOL:
        if (!value.is_boolean()) fail(path, "expected true or false (got " + kind_of(value) + ")");
        break;
      case FieldDescriptor::CPPTYPE_STRING:
        if (!value.is_string()) fail(path, "expected text in quotes (got " + kind_of(value) + ")");
        break;
      case FieldDescriptor::CPPTYPE_ENUM:
        if (value.is_string() && field.enum_type()->FindValueByName(value.get<std::string>()) == nullptr) {
          std::vector<std::string> names;
          for (int i = 0; i < field.enum_type()->value_count(); ++i)
            names.push_back(field.enum_type()->value(i)->name());
          fail(path, "unknown value " + shown(value) + " (one of: " + util::joined(names) + ")");
        } else if (!value.is_string() && !value.is_number_integer()) {
          fail(path, "expected one of the names in quotes (got " + kind_of(value) + ")");
        }
        break;
      case FieldDescriptor::CPPTYPE_MESSAGE:
        message(*field.message_type(), value, path);
        break;
    }
  }

  std::vector<Problem>& problems_;
};

}  // namespace

std::vector<Problem> schema_problems(const nlohmann::ordered_json& document, const Descriptor& type) {
  std::vector<Problem> problems;
  SchemaChecker(problems).message(type, document, "");
  return problems;
}

}  // namespace optique::config
