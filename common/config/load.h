#pragma once
// Reading an installation file: JSON through Protobuf's parser into its schema,
// then parsed into the typed installation (config/parse.h). A failure names the
// file, the field path and the problem.

#include <string>

#include "config/installation.h"
#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

struct LoadedConfig {
  Installation installation;  // checked, defaults applied, geometry resolved
  std::string path;           // as given
  std::string directory;      // for relative asset paths
  std::string sha256;         // of the file's bytes, hex
};

[[nodiscard]] Result<LoadedConfig> load_installation(const std::string& path);

// JSON text that came from `origin` (a file name, for messages) as the schema,
// unchecked: syntax errors say the line and column, unknown fields their path.
[[nodiscard]] Result<schema::Installation> read_schema(const std::string& json, const std::string& origin);

// Parses and checks JSON text; `directory` resolves relative asset paths.
[[nodiscard]] Result<Installation> parse_installation(const std::string& json, const std::string& origin,
                                                      const std::string& directory);

}  // namespace optique::config
