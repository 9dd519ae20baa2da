#include "check_config.h"

#include <map>
#include <sstream>

namespace optique::master {

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
    const auto& r = p.region();
    out << "    " << p.id() << ": " << p.width() << "×" << p.height() << " px on " << p.screen() << " [" << r.x()
        << ", " << r.y() << "] + " << r.width() << " × " << r.height() << " m, host " << p.host() << ", "
        << p.output().kind() << ", eye " << p.eye() << "\n";
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
      << m.frame_rate() << " Hz, frame timeout " << m.frame_timeout_ms() << " ms, present lead " << m.present_lead_us()
      << " µs\n";
  out << "  scene: "
      << (inst.scene().builtin().empty() ? "glTF " + inst.scene().gltf() : "builtin " + inst.scene().builtin()) << "\n";
  return out.str();
}

}  // namespace optique::master
