#include "tools/check_config.h"

#include <iomanip>
#include <map>
#include <sstream>

#include "config/geometry.h"

namespace optique::tools {
namespace {

// Where a calibrated projector lands: the lit quad's bounding box on the screen,
// and what the single pass keeps of the depth range.
std::string keystoned_summary(const config::Installation& inst, const config::Projector& p) {
  auto geometry = config::projector_geometry(p);
  if (!geometry) return "(" + geometry.error() + ")";
  for (const auto& screen : inst.screens()) {
    if (screen.id() != p.screen()) continue;
    auto oblique = geometry::oblique_projection(geometry.value(), config::usable_area(screen));
    if (!oblique) return "(" + oblique.error() + ")";
    const auto& b = oblique.value().bounds;
    std::ostringstream text;
    text << std::setprecision(3) << "keystoned, lights (within the screen) [" << b.min.x << ", " << b.min.y << "] – ["
         << b.max.x << ", " << b.max.y << "] m, " << (p.rendering().empty() ? "single-pass" : p.rendering())
         << " (depth scale " << oblique.value().depth_scale << ")";
    return text.str();
  }
  return "(unknown screen)";
}

}  // namespace

std::string summarize(const config::LoadedConfig& config) {
  const auto& inst = config.installation;
  std::ostringstream out;
  out << config.path << ": OK";
  if (!inst.name().empty()) out << " — " << inst.name();
  out << "\n  sha256 " << config.sha256 << "\n";
  std::map<std::string, int> per_screen;
  for (const auto& p : inst.projectors()) per_screen[p.screen()] += 1;
  out << "  screens (" << inst.screens_size() << "):\n";
  for (const auto& s : inst.screens()) {
    out << "    " << s.id() << ": " << s.width() << " × " << s.height() << " m at [" << s.origin(0) << ", "
        << s.origin(1) << ", " << s.origin(2) << "], " << per_screen[s.id()] << " projector(s)\n";
  }
  out << "  projectors (" << inst.projectors_size() << "):\n";
  for (const auto& p : inst.projectors()) {
    out << "    " << p.id() << ": " << p.width() << "×" << p.height() << " px on " << p.screen() << " ";
    if (p.homography().empty()) {
      const auto& r = p.region();
      out << "[" << r.x() << ", " << r.y() << "] + " << r.width() << " × " << r.height() << " m";
    } else {
      out << keystoned_summary(inst, p);
    }
    out << ", host " << p.host() << ", " << p.output().kind() << ", eye " << p.eye() << "\n";
  }
  const auto& v = inst.viewer();
  out << "  viewer: ";
  if (v.path().empty()) {
    out << "eye at [" << v.eye(0) << ", " << v.eye(1) << ", " << v.eye(2) << "]";
  } else {
    out << "scripted path of " << v.path_size() << " points over "
        << v.path(v.path_size() - 1).time() - v.path(0).time() << " s";
  }
  out << ", eye separation " << v.eye_separation() << " m\n";
  const auto& m = inst.master();
  out << "  master: " << m.listen() << ":" << m.port() << (m.port() == 0 ? " (ephemeral)" : "") << ", "
      << m.frame_rate() << " Hz, frame timeout " << m.frame_timeout_ms() << " ms (then "
      << (m.straggler_policy() == "drop" ? "drop the frame" : "present without the late node") << "), present lead "
      << m.present_lead_us() << " µs\n";
  out << "  scene: "
      << (inst.scene().builtin().empty() ? "glTF " + inst.scene().gltf() : "builtin " + inst.scene().builtin());
  if (inst.scene().light_switches_size() > 0) {
    out << ", " << inst.scene().light_switches_size() << " light switch(es) from "
        << inst.scene().light_switches(0).time() << " s";
  }
  out << "\n";
  return out.str();
}

}  // namespace optique::tools
