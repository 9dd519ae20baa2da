#pragma once
// A file a config names (a glTF scene, a tracker replay), relative to the
// config's folder, made absolute so that nodes started elsewhere read the same
// file.

#include <string>

namespace optique::config {

[[nodiscard]] std::string resolve_asset(const std::string& path, const std::string& config_dir);

}  // namespace optique::config
