#pragma once
// Reading an installation file: JSON through Protobuf's parser, then validation,
// then defaults. A failure names the file, the field path and the problem.

#include <string>

#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

struct LoadedConfig {
  Installation installation;  // validated, defaults applied
  std::string path;           // as given
  std::string directory;      // for relative asset paths
  std::string sha256;         // of the file's bytes, hex
};

[[nodiscard]] Result<LoadedConfig> load_installation(const std::string& path);

// Parses and checks JSON text that came from `origin` (a file name, for messages).
[[nodiscard]] Result<Installation> parse_installation(const std::string& json, const std::string& origin,
                                                      const std::string& directory);

// Fills every setting the user left at zero/empty with its documented default.
void apply_defaults(Installation& installation);

}  // namespace optique::config
