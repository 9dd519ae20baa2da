#include "master/status/status_service.h"

#include "master/status/page_policy.h"
#include "master/status/status_json.h"
#include "master/status/status_metrics.h"
#include "operator_page.h"

namespace optique::master {

std::shared_ptr<WarningSink> make_warning_sink() {
  auto sink = std::make_shared<WarningSink>(kWarningsShown);
  sink->set_level(spdlog::level::warn);
  sink->set_pattern("%H:%M:%S %v");
  return sink;
}

std::vector<LiveWarning> last_warnings(WarningSink& sink) {
  std::vector<LiveWarning> warnings;
  for (std::string line : sink.last_formatted()) {
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    const auto space = line.find(' ');
    if (space == std::string::npos) {
      warnings.push_back({"", line});
    } else {
      warnings.push_back({line.substr(0, space), line.substr(space + 1)});
    }
  }
  return warnings;
}

StatusService::StatusService(const config::StatusServer& settings, OperatorAccess access, CommandSink on_command,
                             SessionOpener open_session, spdlog::logger& log)
    : settings_(settings),
      access_(std::move(access)),
      on_command_(std::move(on_command)),
      open_session_(std::move(open_session)),
      server_(
          io_,
          [&] {
            http::ServerLimits limits;
            limits.max_connections = settings.max_connections;
            return limits;
          }(),
          [this](const http::Request& request) {
            Routed routed = route(request, access_, board_.get());
            if (routed.command) on_command_(*routed.command, request.peer);
            if (routed.scene_session) {
              if (!open_session_) return http::text_response(404, "this master takes no scene sessions");
              routed.response.websocket = open_session_(*routed.scene_session, request.peer);
            }
            return std::move(routed.response);
          },
          log) {
  board_.set({std::make_shared<const std::string>(pages::operator_page_html),
              std::make_shared<const std::string>(page_security_policy(pages::operator_page_html)), nullptr, nullptr});
}

StatusService::~StatusService() {
  server_.stop();
  if (thread_.joinable()) thread_.join();
}

Result<std::uint16_t> StatusService::start() {
  auto port = server_.listen(settings_.listen, settings_.port);
  if (!port) return Error{"master.status: " + port.error()};
  // The stop() posted by the destructor ends run(): the server then has no work left.
  thread_ = std::thread([this] { io_.run(); });
  return port;
}

void StatusService::publish(const LiveStatus& status) {
  StatusTexts texts = board_.get();
  auto json = std::make_shared<const std::string>(status_json(status));
  texts.json = json;
  texts.metrics = std::make_shared<const std::string>(status_metrics(status));
  board_.set(std::move(texts));
  server_.publish(std::move(json));
}

LiveClients StatusService::clients() const {
  const http::ServerCounts counts = server_.counts();
  return {counts.open, counts.streams, counts.requests,
          counts.refused_busy + counts.refused_address + counts.timed_out + counts.too_large + counts.bad_requests +
              counts.streams_behind};
}

}  // namespace optique::master
