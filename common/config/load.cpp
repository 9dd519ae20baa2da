#include "config/load.h"

#include <google/protobuf/util/json_util.h>

#include <nlohmann/json.hpp>

#include <filesystem>

#include "config/parse.h"
#include "config/schema_check.h"
#include "util/read_file.h"
#include "util/sha256.h"

namespace optique::config {

Result<schema::Installation> read_schema(const std::string& json, const std::string& origin) {
  // Protobuf's parser says what is wrong with JSON syntax but not where; a user
  // with a missing comma in a long file needs the line and column.
  nlohmann::ordered_json document;
  try {
    document = nlohmann::ordered_json::parse(json);
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    const auto detail = what.find(": ");
    if (detail != std::string::npos) what = what.substr(detail + 2);
    std::size_t line = 1;
    std::size_t column = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < json.size(); ++i) {
      if (json[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    return Error{origin + ":" + std::to_string(line) + ":" + std::to_string(column) + ": not valid JSON: " + what};
  }
  // Every unknown field and value of the wrong kind at once, in our words;
  // Protobuf's parser only sees what this check does not (and stops at the first).
  if (const auto problems = schema_problems(document, *schema::Installation::descriptor()); !problems.empty()) {
    return Error{describe_problems(problems, origin)};
  }
  schema::Installation installation;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &installation, options);
  if (!status.ok()) {
    return Error{origin + ": not a valid installation: " + std::string(status.message())};
  }
  return installation;
}

Result<Installation> parse_installation(const std::string& json, const std::string& origin,
                                        const std::string& directory) {
  auto schema = read_schema(json, origin);
  if (!schema) return Error{schema.error()};
  return parse_installation(schema.value(), directory, origin);
}

Result<LoadedConfig> load_installation(const std::string& path) {
  auto text = util::read_file(path, "config file");
  if (!text) return Error{text.error()};

  LoadedConfig loaded;
  loaded.path = path;
  loaded.directory = std::filesystem::path(path).parent_path().string();
  if (loaded.directory.empty()) loaded.directory = ".";
  auto installation = parse_installation(text.value(), path, loaded.directory);
  if (!installation) return Error{installation.error()};
  loaded.installation = std::move(installation).value();
  loaded.sha256 = util::sha256_hex(text.value());
  return loaded;
}

}  // namespace optique::config
