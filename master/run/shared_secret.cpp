#include "master/run/shared_secret.h"

#include <filesystem>

namespace optique::master {

std::string secret_path(const config::LoadedConfig& config) {
  const std::string& file = config.installation.master.secret_file;
  if (file.empty()) return {};
  const std::filesystem::path path(file);
  return path.is_absolute() ? path.string() : (std::filesystem::path(config.directory) / path).string();
}

Result<std::optional<net::Secret>> load_installation_secret(const config::LoadedConfig& config) {
  const std::string path = secret_path(config);
  if (path.empty()) return std::optional<net::Secret>{};
  auto secret = net::load_secret_file(path);
  if (!secret) return Error{secret.error()};
  return std::optional<net::Secret>(std::move(secret).value());
}

}  // namespace optique::master
