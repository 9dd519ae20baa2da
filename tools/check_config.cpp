#include "tools/check_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "config/address.h"
#include "config/load.h"

namespace optique::tools {
namespace {

// Where a calibrated projector lands: the lit quad's bounding box on the screen,
// and what the single pass keeps of the depth range.
std::string keystoned_summary(const config::Installation& inst, const config::Projector& p) {
  auto oblique = geometry::oblique_projection(p.geometry(), inst.screen_of(p).area());
  if (!oblique) return "(" + oblique.error() + ")";
  const auto& b = oblique.value().bounds;
  std::ostringstream text;
  text << std::setprecision(3) << "keystoned, lights (within the screen) [" << b.min.x << ", " << b.min.y << "] – ["
       << b.max.x << ", " << b.max.y << "] m, " << config::to_string(p.rendering) << " (depth scale over the lit area "
       << oblique.value().depth_scale << ")";
  return text.str();
}

// A DLP projector's fields in display order, with their times in milliseconds
// at the master's frame rate: "colour fields (per-field): B −1.67 ms, R 0 ms, …".
std::string color_fields_summary(const config::ColorFields& c, const config::MasterSettings& master) {
  std::vector<config::ColorField> fields = c.fields;
  std::sort(fields.begin(), fields.end(), [](const auto& a, const auto& b) { return a.offset < b.offset; });
  const double period_ms = 1000.0 / master.frame_rate;
  std::ostringstream text;
  text << std::setprecision(3) << "colour fields (" << config::to_string(c.method) << ", " << c.images
       << (c.images == 1 ? " image" : " images") << " per frame): ";
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string_view name = config::to_string(fields[i].channel);
    text << (i ? ", " : "") << static_cast<char>(std::toupper(name.front()));
    if (c.images > 1) text << fields[i].image;
    text << " " << fields[i].offset * period_ms << " ms (" << fields[i].duration * period_ms << " ms long)";
  }
  text << " from the display time";
  if (c.method == config::FieldMethod::gather) text << "; " << c.gather_samples << " samples per field and pixel";
  if (c.velocity_threshold > 0.0) {
    text << "; velocity_threshold " << c.velocity_threshold << " px per frame";
    if (c.method == config::FieldMethod::off) {
      text << " has no effect with method off (no field offsets to replace)";
    } else {
      text << ": faster pixels get motion blur over " << (c.images > 1 ? "their image's half of " : "")
           << "the frame instead"
           << (c.method == config::FieldMethod::per_field ? " (from one more render, with velocity)" : "");
    }
  }
  return text.str();
}

}  // namespace

std::string summarize(const config::LoadedConfig& config) {
  const config::Installation& inst = config.installation;
  std::ostringstream out;
  out << config.path << ": OK";
  if (!inst.name.empty()) out << " — " << inst.name;
  out << "\n  sha256 " << config.sha256 << "\n";
  std::vector<int> per_screen(inst.screens.size(), 0);
  for (const config::Projector& p : inst.projectors) per_screen[p.screen] += 1;
  out << "  screens (" << inst.screens.size() << "):\n";
  for (std::size_t i = 0; i < inst.screens.size(); ++i) {
    const config::Screen& s = inst.screens[i];
    out << "    " << s.id << ": " << s.width << " × " << s.height << " m at [" << s.origin.x << ", " << s.origin.y
        << ", " << s.origin.z << "], " << per_screen[i] << " projector(s)\n";
  }
  out << "  projectors (" << inst.projectors.size() << "):\n";
  for (const config::Projector& p : inst.projectors) {
    out << "    " << p.id << ": " << p.width << "×" << p.height << " px on " << inst.screen_of(p).id << " ";
    if (p.region) {
      const geometry::ScreenRect& r = *p.region;
      out << "[" << r.min.x << ", " << r.min.y << "] + " << r.width() << " × " << r.height() << " m";
    } else {
      out << keystoned_summary(inst, p);
    }
    out << ", host " << p.host << ", " << config::to_string(p.output.kind) << ", eye " << config::to_string(p.eye)
        << "\n";
    if (!p.color_fields.fields.empty()) out << "      " << color_fields_summary(p.color_fields, inst.master) << "\n";
    if (p.up_conversion.enabled()) {
      const config::UpConversion& up = p.up_conversion;
      out << "      up-conversion: a key frame every " << up.ratio << " frames (" << inst.master.frame_rate / up.ratio
          << " key frames a second), the others by " << config::to_string(up.method) << ", "
          << config::to_string(up.mode)
          << (up.mode == config::UpMode::interpolate
                  ? " (between the key frames before and after: the master sends each key frame's scene " +
                        std::to_string(up.frames_ahead()) + " frames ahead)"
              : up.spread ? " (from the last key frame drawn; each is used " + std::to_string(up.ratio) + "…" +
                                std::to_string(2 * up.ratio - 1) + " frames after its moment)"
                          : " (from the last key frame)")
          << (up.spread ? ", each key frame drawn a band a frame" : "")
          << (up.adaptive() ? ", fewer frames between while they would fall below " +
                                  std::to_string(static_cast<int>(std::lround(up.min_psnr))) + " dB PSNR_Y"
                            : ", the ratio fixed")
          << (p.color_fields.sequential() ? "; every colour field built from the key frames at its own moment" : "")
          << "\n";
    }
  }
  const config::Viewer& v = inst.viewer;
  out << "  viewer: ";
  if (!v.moves()) {
    const glm::dvec3& eye = v.path.front().position;
    out << "eye at [" << eye.x << ", " << eye.y << ", " << eye.z << "]";
  } else {
    out << "scripted path of " << v.path.size() << " points over " << v.path.back().time - v.path.front().time << " s";
  }
  out << ", eye separation " << v.eye_separation << " m\n";
  if (v.tracking) {
    const config::Tracking& t = *v.tracking;
    out << "  tracking: ";
    if (t.source == config::TrackingSource::dtrack) {
      out << "DTrack's ASCII output on " << t.listen << ":" << t.port << " (UDP)"
          << (t.from.empty() ? std::string() : " from " + t.from + " only") << ", body " << t.body;
    } else {
      out << "replay of " << t.file << " (looped)";
    }
    out << "; the head predicted at each display time by " << config::to_string(t.prediction);
    if (t.prediction == config::HeadPrediction::double_exponential) out << " (alpha " << t.smoothing << ")";
    out << ", latency " << static_cast<double>(t.latency.count()) / 1000.0 << " ms";
    out << "; lost after " << t.lost_after.count() << " ms: the last pose held " << t.hold.count()
        << " ms, then eased to the eye above over " << t.ease.count() << " ms\n";
  }
  const config::MasterSettings& m = inst.master;
  out << "  master: " << m.listen << ":" << m.port << (m.port == 0 ? " (ephemeral)" : "") << ", " << m.frame_rate
      << " Hz, frame timeout " << m.frame_timeout.count() << " ms (then "
      << (m.straggler_policy == config::StragglerPolicy::drop ? "drop the frame" : "present without the late node")
      << "), present lead " << m.present_lead.count() << " µs\n";
  if (m.status) {
    const std::string& listen = m.status->listen;
    const std::string host = listen.find(':') != std::string::npos ? "[" + listen + "]" : listen;
    // Port 0 is no address to open: the master takes a free one and logs it.
    out << "  status: "
        << (m.status->port == 0 ? "on " + host + ", an ephemeral port the master logs when it starts"
                                : "http://" + host + ":" + std::to_string(m.status->port) + "/")
        << " (page, /status.json, /metrics); "
        << (config::is_loopback_address(listen) ? "reads open on loopback" : "reads need the token") << ", "
        << (m.secret_file.empty() ? "controls off (they need a token, and there is no master.secret_file)"
                                  : "controls need the token")
        << "; at most " << m.status->max_connections << " connections\n";
  }
  if (m.api) {
    const std::string host = m.api->listen.find(':') != std::string::npos ? "[" + m.api->listen + "]" : m.api->listen;
    out << "  api: scene sessions on " << host << ":"
        << (m.api->port == 0 ? "an ephemeral port the master logs when it starts" : std::to_string(m.api->port))
        << (config::is_loopback_address(m.api->listen) ? "" : ", applications prove the shared secret") << "; at most "
        << m.api->max_sessions << " sessions, " << m.api->max_instances << " instances, " << m.api->max_edits_per_frame
        << " edits a frame; models loaded from " << m.api->assets
        << "; an edit made before frame k begins is in frame k";
    // Key frames drawn ahead cannot know a later edit.
    for (const config::Projector& p : inst.projectors) {
      if (p.up_conversion.frames_ahead() > 0) {
        out << "; on " << p.id << " (interpolating) " << p.up_conversion.frames_ahead() << " frames later";
      }
    }
    out << "\n";
  }
  out << "  scene: " << (inst.scene.builtin.empty() ? "glTF " + inst.scene.gltf : "builtin " + inst.scene.builtin);
  if (!inst.scene.light_switches.empty()) {
    out << ", " << inst.scene.light_switches.size() << " light switch(es) from "
        << inst.scene.light_switches.front().time << " s";
  }
  out << "\n";
  return out.str();
}

}  // namespace optique::tools
