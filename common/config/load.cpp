#include "config/load.h"

#include <google/protobuf/util/json_util.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "config/defaults.h"
#include "config/geometry.h"
#include "config/validate.h"
#include "util/sha256.h"

namespace optique::config {

Result<Installation> parse_installation(const std::string& json, const std::string& origin,
                                        const std::string& directory) {
  // Protobuf's parser says what is wrong with JSON syntax but not where; a user
  // with a missing comma in a long file needs the line and column.
  try {
    [[maybe_unused]] const auto document = nlohmann::json::parse(json);
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    const auto detail = what.find(": ");
    if (detail != std::string::npos) what = what.substr(detail + 2);
    std::size_t line = 1;
    std::size_t column = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < json.size(); ++i) {
      if (json[i] == '\n') {
        ++line;
        column = 1;
      } else {
        ++column;
      }
    }
    return Error{origin + ":" + std::to_string(line) + ":" + std::to_string(column) + ": not valid JSON: " + what};
  }
  Installation installation;
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;
  const auto status = google::protobuf::util::JsonStringToMessage(json, &installation, options);
  if (!status.ok()) {
    return Error{origin + ": not a valid installation: " + std::string(status.message())};
  }
  const std::vector<Problem> problems = validate(installation, directory);
  if (!problems.empty()) return Error{describe_problems(problems, origin)};
  apply_defaults(installation);
  const std::vector<Problem> geometry = resolve_geometry(installation, directory);
  if (!geometry.empty()) return Error{describe_problems(geometry, origin)};
  return installation;
}

Result<LoadedConfig> load_installation(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path + ": cannot open the config file"};
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return Error{path + ": cannot read the config file"};

  LoadedConfig loaded;
  loaded.path = path;
  loaded.directory = std::filesystem::path(path).parent_path().string();
  if (loaded.directory.empty()) loaded.directory = ".";
  auto installation = parse_installation(text.str(), path, loaded.directory);
  if (!installation) return Error{installation.error()};
  loaded.installation = std::move(installation).value();
  loaded.sha256 = util::sha256_hex(text.str());
  return loaded;
}

void apply_defaults(Installation& installation) {
  MasterSettings& m = *installation.mutable_master();
  if (m.listen().empty()) m.set_listen("0.0.0.0");
  if (m.frame_rate() == 0.0) m.set_frame_rate(defaults::kFrameRate);
  if (m.frame_timeout_ms() == 0) m.set_frame_timeout_ms(defaults::kFrameTimeoutMs);
  if (m.startup_timeout_ms() == 0) m.set_startup_timeout_ms(defaults::kStartupTimeoutMs);
  if (m.handshake_timeout_ms() == 0) m.set_handshake_timeout_ms(defaults::kHandshakeTimeoutMs);
  if (m.heartbeat_ms() == 0) m.set_heartbeat_ms(defaults::kHeartbeatMs);
  if (m.liveness_timeout_ms() == 0)
    m.set_liveness_timeout_ms(std::max(defaults::kMinLivenessTimeoutMs, 3 * m.heartbeat_ms()));
  if (m.present_lead_us() == 0) m.set_present_lead_us(defaults::kPresentLeadUs);
  if (m.max_message_bytes() == 0) m.set_max_message_bytes(defaults::kMaxMessageBytes);
  if (m.max_pending_connections() == 0) m.set_max_pending_connections(defaults::kMaxPendingConnections);
  if (m.straggler_policy().empty()) m.set_straggler_policy("present");

  Viewer& v = *installation.mutable_viewer();
  if (v.eye_separation() == 0.0) v.set_eye_separation(defaults::kEyeSeparation);
  if (v.near() == 0.0) v.set_near(defaults::kNear);
  if (v.far() == 0.0) v.set_far(defaults::kFar);
  if (v.head_right().empty()) {
    v.add_head_right(1.0);
    v.add_head_right(0.0);
    v.add_head_right(0.0);
  }

  if (installation.has_depth_of_field()) {
    DepthOfField& d = *installation.mutable_depth_of_field();
    if (d.near() == 0.0) d.set_near(v.near());
    if (d.far() == 0.0) d.set_far(v.far());
  }

  for (Screen& s : *installation.mutable_screens()) {
    if (s.pixels_per_metre() == 0.0) s.set_pixels_per_metre(defaults::kPixelsPerMetre);
  }
  for (Projector& p : *installation.mutable_projectors()) {
    if (p.host().empty()) p.set_host("localhost");
    if (p.output().kind().empty()) p.mutable_output()->set_kind("headless");
    if (p.eye().empty()) p.set_eye("mono");
    if (p.content().role().empty()) p.mutable_content()->set_role("full");
    if (p.content().role() == "defocus" && p.content().blur_radius() == 0.0) {
      p.mutable_content()->set_blur_radius(defaults::kBlurRadius);
    }
    if (p.brightness() == 0.0) p.set_brightness(1.0);
    const bool other_geometry = !p.homography().empty() || !p.calibration().empty() || p.has_camera();
    if (!p.has_region() && !other_geometry) {
      for (const Screen& s : installation.screens()) {
        if (s.id() != p.screen()) continue;
        Region& r = *p.mutable_region();
        r.set_x(0.0);
        r.set_y(0.0);
        r.set_width(s.width());
        r.set_height(s.height());
      }
    }
  }
}

}  // namespace optique::config
