// Places two copies of the installation's scene and moves one on a circle in
// front of the wall, a step every frame, for a few seconds, while the other
// turns red and back and the scene's point lights go dark one at a time, a
// second each: the C++ twin of clients/python/examples/circle.py.
//   optique-master --config configs/powerwall-2x2.json --local --api-port 7490
//   optique-example-circle --seconds 10

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <thread>

#include "clients/cpp/session.h"

namespace {

// Fails with the master's message, or the refusal's field and reason.
bool applied(const optique::Result<optique::client::Outcome>& outcome, std::uint64_t& frame) {
  if (!outcome) {
    std::cerr << "circle: " << outcome.error() << "\n";
    return false;
  }
  if (!outcome.value().applied()) {
    std::cerr << "circle: refused: " << outcome.value().refused->field() << ": " << outcome.value().refused->reason()
              << "\n";
    return false;
  }
  frame = outcome.value().frame;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"moves a copy of the installation's scene on a circle (the scene session's C++ client)"};
  optique::client::Options options;
  options.name = "circle-cpp";
  double seconds = 5.0;
  double radius = 0.4;
  app.add_option("--host", options.host, "the master's address");
  app.add_option("--port", options.port, "its master.api port");
  app.add_option("--secret-file", options.secret_file, "the installation's shared secret, where the master needs it");
  app.add_option("--seconds", seconds, "how long to move it");
  app.add_option("--radius", radius, "metres");
  CLI11_PARSE(app, argc, argv);

  auto session = optique::client::Session::connect(options);
  if (!session) {
    std::cerr << "circle: " << session.error() << "\n";
    return 1;
  }
  auto& wall = *session.value();
  if (wall.scene().assets_size() == 0) {
    std::cerr << "circle: the master has no asset to place\n";
    return 1;
  }
  const std::string asset = wall.scene().assets(0);  // the installation's own scene
  optique::client::Transaction place;
  for (const auto& instance : wall.scene().instances()) {
    // What an earlier run left (a master restarted from its journal keeps it).
    if (instance.instance() == "orbit-cpp" || instance.instance() == "beacon-cpp") place.remove(instance.instance());
  }
  place.create("orbit-cpp", asset, {{{radius, 0.0, 0.3}}, std::nullopt, {{0.25, 0.25, 0.25}}});
  place.create("beacon-cpp", asset, {{{0.0, 0.0, 0.3}}, std::nullopt, {{0.15, 0.15, 0.15}}});
  std::uint64_t first = 0;
  if (!applied(wall.apply(place), first)) return 1;
  std::cout << "placed from frame " << first << "\n";

  const auto start = std::chrono::steady_clock::now();
  std::uint64_t last = first;
  int moves = 0;
  int switches = 0;
  const std::uint32_t lights = wall.scene().light_count();
  std::uint32_t dark = 0;  // the light off now, counting from 1 (0: none yet)
  for (;;) {
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (now >= seconds) break;
    const double angle = now * 2.0 * M_PI / 4.0;  // a turn every 4 s
    const double red = 0.5 + 0.5 * std::sin(3.0 * now);
    optique::client::Transaction step;
    step.move("orbit-cpp", {{{radius * std::cos(angle), radius * std::sin(angle), 0.3}},
                            {{std::cos(angle / 2), 0.0, std::sin(angle / 2), 0.0}},
                            std::nullopt});
    step.tint("beacon-cpp", {1.0, 1.0 - red, 1.0 - red, 1.0});
    if (const auto second = static_cast<std::uint32_t>(now); lights > 0 && second + 1 != dark) {
      if (dark != 0) step.switch_light((dark - 1) % lights, true);
      step.switch_light(second % lights, false);
      dark = second + 1;
      ++switches;
    }
    if (!applied(wall.apply(step), last)) return 1;
    ++moves;
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
  }
  if (dark != 0) {  // every light as the config has it again
    optique::client::Transaction lit;
    lit.switch_light((dark - 1) % lights, true);
    if (!applied(wall.apply(lit), last)) return 1;
  }
  std::cout << "moved it " << moves << " times, frames " << first << " to " << last << "; switched a light " << switches
            << " times\n";
  return 0;
}
