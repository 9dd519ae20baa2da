#include "node/cli.h"

#include <sched.h>
#include <sys/prctl.h>

#include <cerrno>
#include <cstring>

#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <iostream>

#include "log/logger.h"
#include "node/node.h"
#include "node/null_renderer.h"
#include "util/program.h"

namespace optique::node {

int run_cli(int argc, char** argv, const GlRendererFactory& make_gl) {
  CLI::App app{"optique-node: renders one projector's share of the picture in sync with the master"};
  // --help shows each option's default (the value it starts with below).
  app.option_defaults()->always_capture_default();
  NodeOptions options;
  std::string master = "127.0.0.1:7400";
  std::string log_level = "info";
  std::int64_t give_up_ms = 10000;
  std::int64_t clock_offset_ns = 0;
  double clock_drift_ppm = 0.0;
  app.add_option("-m,--master", master, "the master's HOST:PORT")->required();
  app.add_option("-i,--id", options.protocol.id, "the projector this node drives (its id in the installation)")
      ->required();
  app.add_option("--give-up-after-ms", give_up_ms, "exit when the master is unreachable this long")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{86'400'000}));
  std::string renderer_kind = "gl";
  std::string capture_dir;
  app.add_option("--renderer", renderer_kind,
                 "gl: draw the scene (headless or in a window, as the config says); "
                 "null: draw nothing (to measure the cluster alone)")
      ->check(CLI::IsMember({"gl", "null"}));
  app.add_option("--capture-dir", capture_dir, "where captured frames go (default: captures/<id>)");
  std::string on_master_lost = "black";
  app.add_option("--on-master-lost", on_master_lost,
                 "black: show black while reconnecting (default); hold: keep showing the last frame")
      ->check(CLI::IsMember({"black", "hold"}));
  std::string secret_file;
  app.add_option("--secret-file", secret_file,
                 "the installation's shared secret (the file its master.secret_file names; mode 600)");
  app.add_option("--cache-dir", options.cache_dir,
                 "where copies of the master's glTF scenes are kept, in its scenes/ (default: $CACHE_DIRECTORY, "
                 "else $XDG_CACHE_HOME/optique, else ~/.cache/optique)");
  std::uint64_t most_scene_mb = options.protocol.most_scene_bytes >> 20;
  app.add_option("--max-scene-mb", most_scene_mb, "the largest scene (all its files, MiB) to fetch from the master")
      ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{1} << 24));
  app.add_option("--log-level", log_level, "trace, debug, info, warn or error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  int realtime_priority = 0;
  app.add_option("--realtime-priority", realtime_priority,
                 "run with real-time priority (SCHED_FIFO, as chrt -f) where permitted; 0: normal priority")
      ->check(CLI::Range(0, 99));
  // Test hooks, hidden from --help.
  app.add_option("--protocol-version", options.protocol.faults.protocol_version, "speak this protocol version")
      ->group("");
  app.add_option("--clock-offset-ns", clock_offset_ns, "skew this node's clock")->group("");
  app.add_option("--clock-drift-ppm", clock_drift_ppm, "make this node's clock drift")->group("");
  std::int64_t present_spin_us = options.present_spin.count();
  app.add_option("--present-spin-us", present_spin_us, "spin this long before each present deadline")
      ->check(CLI::Range(std::int64_t{0}, std::int64_t{5000}))
      ->group("");
  app.add_option("--corrupt-state-at-frame", options.protocol.faults.corrupt_state_at_frame,
                 "nudge the scene state at this frame")
      ->group("");
  app.add_option("--lag-frames", options.protocol.faults.lag_frames, "show the content of this many frames ago")
      ->check(CLI::Range(0u, 100u))
      ->group("");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? kExitOk : kExitRefused;
  }
  const auto colon = master.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == master.size()) {
    std::cerr << "optique-node: --master must be HOST:PORT (got '" << master << "')\n";
    return kExitRefused;
  }
  options.protocol.master = master;
  options.master_host = master.substr(0, colon);
  options.master_port = master.substr(colon + 1);
  if (options.master_host.front() == '[' && options.master_host.back() == ']') {
    options.master_host = options.master_host.substr(1, options.master_host.size() - 2);  // [::1]:7400
  }
  options.protocol.give_up_after = std::chrono::milliseconds(give_up_ms);
  options.present_spin = std::chrono::microseconds(present_spin_us);
  options.protocol.hold_last_frame = on_master_lost == "hold";
  options.protocol.most_scene_bytes = most_scene_mb << 20;
  options.protocol.needs_scene_files = renderer_kind != "null";
  options.protocol.clock = clock::LocalClock(clock_offset_ns, clock_drift_ppm);
  if (!secret_file.empty()) {
    auto secret = net::load_secret_file(secret_file);
    if (!secret) {
      std::cerr << "optique-node: --secret-file: " << secret.error() << "\n";
      return kExitRefused;
    }
    options.protocol.secret = std::move(secret).value();
  }

  if (renderer_kind == "gl" && !make_gl) {
    const std::vector<std::string> args(argv + 1, argv + argc);
    const Error failed = util::replace_process(util::sibling_program("optique-node-gl"), argv[0], args);
    std::cerr << "optique-node: the GL renderer: " << failed.message << " (or run with --renderer null)\n";
    return kExitRefused;
  }

  // The kernel may wake a sleeper up to its timer slack late (50 µs by default);
  // presents are timed to tens of microseconds.
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  auto logger = log::make_logger("node " + options.protocol.id, log_level);
  if (realtime_priority > 0) {
    // Before any thread starts, so that the renderer's threads have it too (as
    // under chrt). Not permitted (no CAP_SYS_NICE, RLIMIT_RTPRIO too low): said,
    // and the node runs at normal priority.
    sched_param param{};
    param.sched_priority = realtime_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &param) == 0) {
      logger->info("real-time priority {} (SCHED_FIFO)", realtime_priority);
    } else {
      logger->warn(
          "running at normal priority: real-time priority {} is not permitted ({}; the systemd unit's "
          "LimitRTPRIO, or rtprio in /etc/security/limits.conf, allows it)",
          realtime_priority, std::strerror(errno));
    }
  }
  boost::asio::io_context io;
  if (capture_dir.empty()) capture_dir = "captures/" + options.protocol.id;
  std::unique_ptr<Renderer> renderer;
  if (renderer_kind == "null") {
    renderer = std::make_unique<NullRenderer>();
  } else {
    renderer = make_gl(*logger, capture_dir);
  }
  Node node(io, std::move(options), *renderer, *logger);
  node.start();
  io.run();
  return node.exit_code();
}

}  // namespace optique::node
