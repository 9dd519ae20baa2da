#include "log/logger.h"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include "log/escape.h"

namespace optique::log {
namespace {

// Escapes each record's message once, before any sink sees it: sinks added or
// given another pattern later (the master's status line, the operator page's
// warnings) are covered too, which a formatter set per sink would not be.
class EscapingLogger final : public spdlog::logger {
 public:
  using spdlog::logger::logger;

  std::shared_ptr<spdlog::logger> clone(std::string name) override {
    auto cloned = std::make_shared<EscapingLogger>(*this);
    cloned->name_ = std::move(name);
    return cloned;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    const std::string_view payload(msg.payload.data(), msg.payload.size());
    if (!needs_escaping(payload)) {
      spdlog::logger::sink_it_(msg);
      return;
    }
    const std::string escaped = escape_for_log(payload);
    spdlog::details::log_msg safe = msg;
    safe.payload = escaped;
    spdlog::logger::sink_it_(safe);
  }
};

}  // namespace

std::shared_ptr<spdlog::logger> make_logger(const std::string& name, const std::string& level, const std::string& file,
                                            FileMode mode) {
  std::vector<spdlog::sink_ptr> sinks;
  sinks.push_back(std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  if (!file.empty())
    sinks.push_back(std::make_shared<spdlog::sinks::basic_file_sink_mt>(file, mode == FileMode::truncate));
  auto logger = std::make_shared<EscapingLogger>(name, sinks.begin(), sinks.end());
  logger->set_pattern("%H:%M:%S.%e %^%-5l%$ [%n] %v");
  logger->set_level(spdlog::level::from_str(level));
  logger->flush_on(spdlog::level::info);
  return logger;
}

}  // namespace optique::log
