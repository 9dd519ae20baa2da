#include "config/asset_path.h"

#include <filesystem>

namespace optique::config {

std::string resolve_asset(const std::string& path, const std::string& config_dir) {
  const std::filesystem::path asset(path);
  if (asset.is_absolute()) return asset.lexically_normal().string();
  return std::filesystem::absolute(std::filesystem::path(config_dir) / asset).lexically_normal().string();
}

}  // namespace optique::config
