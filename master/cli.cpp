#include "cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <filesystem>
#include <iostream>

#include <spdlog/sinks/sink.h>
#include "check_config.h"

#include "log/logger.h"
#include "master.h"
#include "render_reference.h"

namespace optique::master {
namespace {

// The config and the scene it names: both must load before anything starts.
Result<std::pair<config::LoadedConfig, scene::LoadedScene>> load_config_and_scene(const std::string& path) {
  auto loaded = config::load_installation(path);
  if (!loaded) return Error{loaded.error()};
  auto scene = scene::load_scene(loaded.value().installation.scene(), loaded.value().directory);
  if (!scene) return Error{path + ": scene: " + scene.error()};
  return std::pair{std::move(loaded).value(), std::move(scene).value()};
}

int check_config(const std::vector<std::string>& files) {
  int status = kExitOk;
  for (const auto& file : files) {
    auto loaded = load_config_and_scene(file);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      status = kExitUsage;
      continue;
    }
    std::cout << summarize(loaded.value().first);
    for (const auto& warning : loaded.value().second.warnings) std::cout << "  scene warning: " << warning << "\n";
  }
  return status;
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App app{"optique-master: owns the scene and the clock, and keeps render nodes in frame sync"};
  app.require_subcommand(0, 1);

  MasterOptions options;
  std::string config_path;
  std::string out_dir;
  std::string log_level = "info";
  std::string listen;
  int port = -1;
  bool no_status = false;
  app.add_option("-c,--config", config_path, "installation file (configs/*.json)");
  app.add_flag("--local", options.local, "start one optique-node per projector on this machine (127.0.0.1)");
  app.add_option("-n,--frames", options.frames, "run this many frames, then shut down (default: until Ctrl-C)");
  app.add_option("-o,--out", out_dir, "write run.json, frames.csv and logs here");
  app.add_option("--port", port, "listen on this port (0: ephemeral); overrides the config")
      ->check(CLI::Range(0, 65535));
  app.add_option("--listen", listen, "listen on this address; overrides the config");
  app.add_option("--port-file", options.port_file, "write the port once listening (for scripts)");
  app.add_option("--node-binary", options.node_binary,
                 "optique-node to start with --local (default: next to this one)");
  app.add_option("--node-arg", options.node_args, "extra argument for local nodes, e.g. --node-arg=--log-level=debug");
  app.add_option("--log-level", log_level, "trace, debug, info, warn or error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_option("--node-log-level", options.node_log_level, "log level for local nodes")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_flag("--no-status", no_status, "no live status line, even on a terminal");
  app.add_option("--capture-every", options.capture_every,
                 "nodes write every K-th frame (frame 0, K, 2K, ...); with --local into OUT/nodes/<projector-id>/");

  std::vector<std::string> check_files;
  auto* check = app.add_subcommand("check-config", "validate installation files and print a summary of each");
  check->add_option("files", check_files, "installation files")->required();

  std::string reference_config;
  std::uint64_t reference_frame = 0;
  std::string reference_out;
  auto* reference = app.add_subcommand("render-reference", "draw what a viewer should see on each screen at one frame");
  reference->add_option("--config", reference_config, "installation file")->required();
  reference->add_option("--frame", reference_frame, "frame number (simulation time = frame / frame rate)");
  reference->add_option("--out", reference_out, "writes OUT/reference/<screen-id>/frame-NNNNNN.exr and .png")
      ->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? kExitOk : kExitUsage;
  }

  if (check->parsed()) return check_config(check_files);
  if (reference->parsed()) {
    auto loaded = load_config_and_scene(reference_config);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      return kExitUsage;
    }
    auto logger = log::make_logger("master", log_level);
    if (auto done =
            render_reference(loaded.value().first, loaded.value().second, reference_frame, reference_out, *logger);
        !done) {
      logger->error("{}", done.error());
      return kExitFailed;
    }
    return kExitOk;
  }

  if (config_path.empty()) {
    std::cerr << "optique-master: --config FILE is required (see --help)\n";
    return kExitUsage;
  }
  auto loaded = load_config_and_scene(config_path);
  if (!loaded) {
    std::cerr << loaded.error() << "\n";
    return kExitUsage;
  }
  options.config = std::move(loaded.value().first);
  options.scene = std::move(loaded.value().second);
  auto& settings = *options.config.installation.mutable_master();
  if (options.local) {
    settings.set_listen("127.0.0.1");
    settings.set_port(0);
  }
  if (!listen.empty()) settings.set_listen(listen);
  if (port >= 0) settings.set_port(static_cast<std::uint32_t>(port));
  if (options.node_binary.empty()) options.node_binary = LocalLauncher::sibling_binary("optique-node");

  std::string log_file;
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) {
      std::cerr << "optique-master: cannot create the output folder '" << out_dir << "': " << ec.message() << "\n";
      return kExitUsage;
    }
    log_file = (std::filesystem::path(out_dir) / "master.log").string();
  }
  if (options.local && options.capture_every != 0 && out_dir.empty()) {
    std::cerr << "optique-master: --capture-every with --local needs --out DIR (captures go to DIR/nodes/)\n";
    return kExitUsage;
  }
  options.out_dir = out_dir;
  options.status_line = !no_status && isatty(STDERR_FILENO) == 1;
  auto logger = log::make_logger("master", log_level, log_file);
  // On a terminal, each log line first clears the status line (stderr only, not the log file).
  if (options.status_line) logger->sinks().front()->set_pattern("\r\033[K%H:%M:%S.%e %^%-5l%$ [%n] %v");

  boost::asio::io_context io;
  Master master(io, std::move(options), *logger);
  if (auto started = master.start(); !started) {
    logger->error("{}", started.error());
    return kExitFailed;
  }
  io.run();
  return master.exit_code();
}

}  // namespace optique::master
