#include "master/app/cli.h"

#include "config/asset_path.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <spdlog/sinks/sink.h>

#include "log/logger.h"
#include "master/app/master.h"
#include "master/run/run_config.h"
#include "master/run/shared_secret.h"
#include "util/program.h"

namespace optique::master {
namespace {

// Subcommands that draw, read images or fit calibrations live in optique-tools,
// so that the process running the frame loop loads no image or GL library.
struct Tool {
  const char* name;
  const char* description;
};
constexpr Tool kTools[] = {
    {"check-config", "validate installation files and print a summary of each"},
    {"render-reference", "draw what a viewer should see on each screen at one frame"},
    {"compose", "what each screen receives at one frame, from the nodes' captures"},
    {"perceive", "what an eye that follows motion sees on each screen around one frame, colour fields and all"},
    {"calibrate", "fit a projector's homography (screen → pixels) from measured points"},
};

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
  int status_port = -1;
  int api_port = -1;
  int tracking_port = -1;
  bool print_status_token = false;
  app.add_option("-c,--config", config_path, "installation file (configs/*.json)");
  app.add_flag("--local", options.local, "start one optique-node per projector on this machine (127.0.0.1)");
  app.add_option("-n,--frames", options.run.frames, "run this many frames, then shut down (default: until Ctrl-C)");
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
  app.add_option("--status-port", status_port,
                 "serve the operator page, status and metrics on this port (0: ephemeral); overrides "
                 "master.status.port, and turns it on (on 127.0.0.1) if the config does not")
      ->check(CLI::Range(0, 65535));
  app.add_option("--status-port-file", options.status_port_file,
                 "write the status server's port once listening (for scripts)");
  app.add_option("--api-port", api_port,
                 "take applications' scene sessions on this port (0: ephemeral); overrides master.api.port, and "
                 "turns it on (on 127.0.0.1) if the config does not")
      ->check(CLI::Range(0, 65535));
  app.add_option("--tracking-port", tracking_port,
                 "receive DTrack's output on this UDP port; overrides viewer.tracking.port (a dtrack source)")
      ->check(CLI::Range(1, 65535));
  app.add_option("--api-port-file", options.api_port_file,
                 "write the scene session's port (master.api) once listening (for scripts)");
  app.add_option("--record", options.record_path,
                 "journal every transaction applications make (master.api) in FILE; a master started again with "
                 "the same FILE comes back with the live scene it leaves");
  app.add_option("--replay", options.replay_path,
                 "play the last run of a --record journal again, each transaction in its frame, with no application");
  app.add_flag("--print-status-token", print_status_token,
               "print the status server's bearer token (derived from master.secret_file) and exit");
  app.add_option("--capture-every", options.run.capture_every,
                 "nodes write every K-th frame (frame 0, K, 2K, ...); with --local into OUT/nodes/<projector-id>/");

  std::vector<CLI::App*> tools;
  for (const Tool& tool : kTools) {
    CLI::App* sub = app.add_subcommand(tool.name, tool.description);
    // Everything after the name, --help included, is optique-tools' to read.
    sub->prefix_command();
    sub->set_help_flag();
    tools.push_back(sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? kExitOk : kExitUsage;
  }

  for (CLI::App* tool : tools) {
    if (!tool->parsed()) continue;
    std::vector<std::string> args{"--log-level", log_level, tool->get_name()};
    for (const std::string& arg : tool->remaining()) args.push_back(arg);
    const Error failed = util::replace_process(util::sibling_program("optique-tools"), "optique-master", args);
    std::cerr << "optique-master " << tool->get_name() << ": " << failed.message << "\n";
    return kExitFailed;
  }

  if (config_path.empty()) {
    std::cerr << "optique-master: --config FILE is required (see --help)\n";
    return kExitUsage;
  }
  // The master animates the scene but never draws it: its images stay unread.
  auto loaded = load_run_config(config_path, {});
  if (!loaded) {
    std::cerr << loaded.error() << "\n";
    return kExitUsage;
  }
  options.config = std::move(loaded.value().config);
  options.scene = std::move(loaded.value().scene);
  options.run.replay = std::move(loaded.value().replay);
  auto secret = load_installation_secret(options.config);
  if (!secret) {
    std::cerr << config::describe_problems({{"master.secret_file", secret.error()}}, config_path) << "\n";
    return kExitUsage;
  }
  options.run.secret = std::move(secret).value();
  options.secret_path = secret_path(options.config);
  if (print_status_token) {
    if (!options.run.secret) {
      std::cerr << "optique-master: " << config_path
                << " names no master.secret_file: the status server has no token without one\n";
      return kExitUsage;
    }
    std::cout << net::status_token(*options.run.secret) << "\n";
    return kExitOk;
  }
  config::MasterSettings& settings = options.config.installation.master;
  if (status_port >= 0) {
    if (!settings.status) settings.status.emplace();
    settings.status->port = static_cast<std::uint16_t>(status_port);
  }
  if (tracking_port > 0) {
    auto& tracking = options.config.installation.viewer.tracking;
    if (!tracking || tracking->source != config::TrackingSource::dtrack) {
      std::cerr << "optique-master: --tracking-port: " << config_path
                << " has no viewer.tracking with source dtrack to receive\n";
      return kExitUsage;
    }
    tracking->port = static_cast<std::uint16_t>(tracking_port);
  }
  if (api_port >= 0) {
    if (!settings.api) {
      // As the config would have it with an empty master.api: assets from its folder.
      settings.api.emplace();
      settings.api->assets = config::resolve_asset(".", options.config.directory);
    }
    settings.api->port = static_cast<std::uint16_t>(api_port);
  }
  if (options.local) {
    settings.listen = "127.0.0.1";
    settings.port = 0;
  }
  if (!listen.empty()) settings.listen = listen;
  if (port >= 0) settings.port = static_cast<std::uint16_t>(port);
  if (options.node_binary.empty()) options.node_binary = util::sibling_program("optique-node");

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
  if (options.local && options.run.capture_every != 0 && out_dir.empty()) {
    std::cerr << "optique-master: --capture-every with --local needs --out DIR (captures go to DIR/nodes/)\n";
    return kExitUsage;
  }
  options.out_dir = out_dir;
  // A --local run that captured frames also shows what the screens received.
  const bool local_captures = options.local && options.run.capture_every != 0;
  options.status_line = !no_status && isatty(STDERR_FILENO) == 1;
  auto logger = log::make_logger("master", log_level, log_file);
  // On a terminal, each log line first clears the status line (stderr only, not the log file).
  if (options.status_line) logger->sinks().front()->set_pattern("\r\033[K%H:%M:%S.%e %^%-5l%$ [%n] %v");
  if (settings.status) {
    options.warnings = make_warning_sink();
    logger->sinks().push_back(options.warnings);
  }
  // What the scene file asked for that is left out or assumed (default lights):
  // the operator reads it here, not in each node's log.
  for (const std::string& warning : options.scene.warnings) logger->warn("scene: {}", warning);
  for (const std::string& note : options.scene.notes) logger->info("scene: {}", note);

  boost::asio::io_context io;
  Master master(io, std::move(options), *logger);
  if (auto started = master.start(); !started) {
    logger->error("{}", started.error());
    return kExitFailed;
  }
  io.run();
  const int status = master.exit_code();
  if (status == kExitOk && local_captures) {
    // Every frame all projectors captured, into OUT/screens/, logged into master.log too.
    logger->flush();
    const std::vector<std::string> args{"--log-level", log_level,  "--log-file", log_file,
                                        "compose",     "--config", config_path,  "--every-captured-frame",
                                        "--out",       out_dir};
    auto composed = util::run_program(util::sibling_program("optique-tools"), args);
    if (!composed) {
      logger->error("composites not made: {}", composed.error());
    } else if (composed.value() != 0) {
      logger->error("composites not made: optique-tools compose exited with status {}", composed.value());
    }
  }
  return status;
}

}  // namespace optique::master
