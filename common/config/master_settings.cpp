// The master's settings: where it listens, the frame rate and every timeout,
// the straggler policy, the operator's status server.
#include <algorithm>

#include "config/address.h"
#include "config/asset_path.h"
#include "config/sections.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

template <class T>
T or_default(T value, T fallback) {
  return value == T{} ? fallback : value;
}

void check_port(Checker& check, const std::string& path, std::uint32_t port) {
  if (port > 65535) check.fail(path, "must be 0..65535 (got " + std::to_string(port) + ")");
}

// An address to listen on (empty: loopback); beyond loopback only with the
// shared secret, for `why`.
void check_listen(Checker& check, const std::string& path, const std::string& listen, const schema::MasterSettings& m,
                  const std::string& why) {
  if (listen.empty()) return;
  if (!is_ip_address(listen)) {
    check.fail(path, "'" + listen + "' is not an IPv4 or IPv6 address");
  } else if (!is_loopback_address(listen) && m.secret_file().empty()) {
    check.fail(path, "'" + listen + "' is reached from other machines, so " + why +
                         ": set master.secret_file (or listen on 127.0.0.1)");
  }
}

std::optional<StatusServer> parse_status(const schema::MasterSettings& m, Checker& check) {
  if (!m.has_status()) return std::nullopt;
  const schema::StatusServer& st = m.status();
  check_listen(check, "master.status.listen", st.listen(), m,
               "the status needs a bearer token, derived from the shared secret");
  check_port(check, "master.status.port", st.port());
  if (st.max_connections() > 100000) {
    check.fail("master.status.max_connections",
               "must be at most 100000 (got " + std::to_string(st.max_connections()) + ")");
  }
  StatusServer status;
  if (!st.listen().empty()) status.listen = st.listen();
  if (st.has_port()) status.port = static_cast<std::uint16_t>(st.port());
  status.max_connections = or_default(st.max_connections(), defaults::kStatusMaxConnections);
  return status;
}

// Beyond loopback only with the secret, as the status server.
std::optional<ApiServer> parse_api(const schema::MasterSettings& m, const std::string& config_dir, Checker& check) {
  if (!m.has_api()) return std::nullopt;
  const schema::ApiServer& a = m.api();
  check_listen(check, "master.api.listen", a.listen(), m, "applications must prove they hold the shared secret");
  check_port(check, "master.api.port", a.port());
  if (a.max_sessions() > 1000) {
    check.fail("master.api.max_sessions", "must be at most 1000 (got " + std::to_string(a.max_sessions()) + ")");
  }
  if (a.max_edits_per_frame() > 10000000) {
    check.fail("master.api.max_edits_per_frame",
               "must be at most 10000000 (got " + std::to_string(a.max_edits_per_frame()) + ")");
  }
  if (a.max_instances() > 10000000) {
    check.fail("master.api.max_instances", "must be at most 10000000 (got " + std::to_string(a.max_instances()) + ")");
  }
  ApiServer api;
  if (!a.listen().empty()) api.listen = a.listen();
  if (a.has_port()) api.port = static_cast<std::uint16_t>(a.port());
  api.max_sessions = or_default(a.max_sessions(), defaults::kApiMaxSessions);
  api.max_edits_per_frame = or_default(a.max_edits_per_frame(), defaults::kApiMaxEditsPerFrame);
  api.max_instances = or_default(a.max_instances(), defaults::kApiMaxInstances);
  api.assets = resolve_asset(a.assets().empty() ? "." : a.assets(), config_dir);
  return api;
}

}  // namespace

MasterSettings parse_master(const schema::MasterSettings& m, const std::string& config_dir, Checker& check) {
  using std::chrono::milliseconds;
  using util::number_text;
  MasterSettings master;
  if (!m.listen().empty()) {
    if (!is_ip_address(m.listen())) check.fail("master.listen", "'" + m.listen() + "' is not an IPv4 or IPv6 address");
    master.listen = m.listen();
  }
  check_port(check, "master.port", m.port());
  master.port = static_cast<std::uint16_t>(m.port());
  if (check.finite("master.frame_rate", m.frame_rate()) && (m.frame_rate() < 0.0 || m.frame_rate() > 1000.0)) {
    check.fail("master.frame_rate",
               "must be in (0, 1000] Hz, or 0 for the default (got " + number_text(m.frame_rate()) + ")");
  }
  master.frame_rate = or_default(m.frame_rate(), defaults::kFrameRate);
  if (const auto policy = from_name(kStragglerPolicyNames, m.straggler_policy())) {
    master.straggler_policy = *policy;
  } else {
    check.fail("master.straggler_policy", "unknown policy '" + m.straggler_policy() +
                                              "' (\"present\": the frame without the late node, or "
                                              "\"drop\": the frame everywhere)");
  }
  if (m.has_min_presented() && check.finite("master.min_presented", m.min_presented()) &&
      (m.min_presented() < 0.0 || m.min_presented() > 1.0)) {
    check.fail("master.min_presented",
               "is a share of the frames, 0 to 1 (got " + number_text(m.min_presented()) + "; 0.9 means 90 %)");
  }
  if (m.has_min_presented()) master.min_presented = m.min_presented();
  if (m.max_message_bytes() != 0 && m.max_message_bytes() < 1024) {
    check.fail("master.max_message_bytes", "must be at least 1024 (got " + std::to_string(m.max_message_bytes()) + ")");
  }
  master.max_message_bytes = or_default(m.max_message_bytes(), defaults::kMaxMessageBytes);
  master.status = parse_status(m, check);
  master.api = parse_api(m, config_dir, check);
  master.frame_timeout = milliseconds(or_default(m.frame_timeout_ms(), defaults::kFrameTimeoutMs));
  master.startup_timeout = milliseconds(or_default(m.startup_timeout_ms(), defaults::kStartupTimeoutMs));
  master.handshake_timeout = milliseconds(or_default(m.handshake_timeout_ms(), defaults::kHandshakeTimeoutMs));
  master.heartbeat = milliseconds(or_default(m.heartbeat_ms(), defaults::kHeartbeatMs));
  const std::uint32_t heartbeat = or_default(m.heartbeat_ms(), defaults::kHeartbeatMs);
  if (m.liveness_timeout_ms() != 0 && m.liveness_timeout_ms() <= 2 * heartbeat) {
    check.fail("master.liveness_timeout_ms", "must be more than twice heartbeat_ms (" + std::to_string(heartbeat) +
                                                 " ms), or peers are dropped between heartbeats");
  }
  // Three heartbeats, or the floor if that is longer.
  master.liveness_timeout =
      milliseconds(or_default(m.liveness_timeout_ms(), std::max(defaults::kMinLivenessTimeoutMs, 3 * heartbeat)));
  master.present_lead = std::chrono::microseconds(or_default(m.present_lead_us(), defaults::kPresentLeadUs));
  master.secret_file = m.secret_file();
  master.max_pending_connections = or_default(m.max_pending_connections(), defaults::kMaxPendingConnections);
  return master;
}

}  // namespace optique::config
