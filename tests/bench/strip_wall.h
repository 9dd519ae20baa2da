#pragma once
// The installation the cluster benches run: one 4 m wall cut into vertical
// strips, one small projector (160×90) and so one node each, the built-in
// cubes. Every node is let through the handshake at once and waited for, so a
// run measures steady frames, not late joins.

#include <algorithm>
#include <cstddef>
#include <sstream>
#include <string>

namespace optique::bench {

// `sealed`: with master.secret_file "secret" (beside the config), so every
// message after the hello is sealed.
[[nodiscard]] inline std::string strip_wall_json(std::size_t nodes, double rate, bool sealed = false) {
  std::ostringstream json;
  const double width = 4.0;
  json << R"({"screens": [{"id": "wall", "origin": [-2, 0, 0], "right": [1, 0, 0], "up": [0, 1, 0], "width": )" << width
       << R"(, "height": 2.25}], "projectors": [)";
  for (std::size_t i = 0; i < nodes; ++i) {
    json << (i ? "," : "") << R"({"id": "n)" << i
         << R"(", "width": 160, "height": 90, "screen": "wall", "region": {"x": )"
         << width * static_cast<double>(i) / static_cast<double>(nodes) << R"(, "y": 0, "width": )"
         << width / static_cast<double>(nodes) << R"(, "height": 2.25}})";
  }
  // Past the default 16 pending connections, and 64 node processes take ~18 s
  // to start on 2 cores.
  json << R"(], "viewer": {"eye": [0, 1.6, 2]}, "master": {"frame_rate": )" << rate
       << R"(, "max_pending_connections": )" << std::max<std::size_t>(16, nodes + 1)
       << R"(, "startup_timeout_ms": 120000)" << (sealed ? R"(, "secret_file": "secret")" : "")
       << R"(}, "scene": {"builtin": "cubes"}})";
  return json.str();
}

}  // namespace optique::bench
