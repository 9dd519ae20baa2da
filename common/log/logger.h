#pragma once
// One logger per process, made in main and handed to whoever logs: no global.

#include <spdlog/logger.h>

#include <memory>
#include <string>

namespace optique::log {

enum class FileMode { truncate, append };

// Logs to stderr (sink 0), and also to `file` (sink 1) when it is not empty. `level` is one of
// spdlog's names: trace, debug, info, warn, error.
[[nodiscard]] std::shared_ptr<spdlog::logger> make_logger(const std::string& name, const std::string& level,
                                                          const std::string& file = {},
                                                          FileMode mode = FileMode::truncate);

}  // namespace optique::log
