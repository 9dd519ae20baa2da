#pragma once
// The installation's shared secret, as the master reads it: the file named by
// master.secret_file, relative to the config file.

#include <optional>
#include <string>

#include "config/load.h"
#include "net/auth.h"
#include "util/result.h"

namespace optique::master {

// The secret file's path as the master opens it; empty when none is configured.
[[nodiscard]] std::string secret_path(const config::LoadedConfig& config);

// Nothing when the installation names no secret file; the secret, or why the
// file is refused ("secret file '…' is readable by other users …").
[[nodiscard]] Result<std::optional<net::Secret>> load_installation_secret(const config::LoadedConfig& config);

}  // namespace optique::master
