#include "cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <spdlog/sinks/sink.h>
#include "calibrate.h"
#include "check_config.h"
#include "compose.h"

#include "light_switches.h"
#include "log/logger.h"
#include "master.h"
#include "render_reference.h"
#include "shared_secret.h"
#include "stacked_groups.h"

namespace optique::master {
namespace {

// The config and the scene it names: both must load before anything starts.
Result<std::pair<config::LoadedConfig, scene::LoadedScene>> load_config_and_scene(const std::string& path) {
  auto loaded = config::load_installation(path);
  if (!loaded) return Error{loaded.error()};
  auto scene = scene::load_scene(loaded.value().installation.scene(), loaded.value().directory);
  if (!scene) return Error{path + ": scene: " + scene.error()};
  const std::size_t light_count = scene.value().definition.lights.size();
  auto problems = check_lighting_groups(loaded.value().installation, light_count);
  for (config::Problem& problem : LightSwitches::check(loaded.value().installation.scene(), light_count)) {
    problems.push_back(std::move(problem));
  }
  if (!problems.empty()) return Error{config::describe_problems(problems, path)};
  // A refused secret file is a config problem: check-config says so too.
  if (auto secret = load_installation_secret(loaded.value()); !secret) {
    return Error{config::describe_problems({{"master.secret_file", secret.error()}}, path)};
  }
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

// Composes every frame that all projectors captured; a frame some node missed
// (it left the barrier) is skipped with a warning.
void compose_local_captures(const config::LoadedConfig& config, const std::string& out_dir, spdlog::logger& log) {
  const auto& projectors = config.installation.projectors();
  if (projectors.empty()) return;
  const std::filesystem::path first = std::filesystem::path(out_dir) / "nodes" / projectors.Get(0).id();
  std::error_code ec;
  std::vector<std::uint64_t> frames;
  for (const auto& entry : std::filesystem::directory_iterator(first, ec)) {
    const std::string name = entry.path().filename().string();
    std::uint64_t frame = 0;
    if (std::sscanf(name.c_str(), "frame-%" SCNu64 ".exr", &frame) == 1 && name.ends_with(".exr")) {
      frames.push_back(frame);
    }
  }
  std::sort(frames.begin(), frames.end());
  for (std::uint64_t frame : frames) {
    if (auto composed = compose_frame(config, frame, (std::filesystem::path(out_dir) / "nodes").string(), out_dir, log);
        !composed) {
      log.warn("frame {} not composed: {}", frame, composed.error());
    }
  }
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
  ReferenceOptions reference_options;
  reference
      ->add_option("--supersample", reference_options.supersample,
                   "S×S samples per pixel, box-filtered (compare with composites, which integrate each pixel)")
      ->check(CLI::Range(1, 8));

  std::string compose_config;
  std::uint64_t compose_frame_number = 0;
  std::string compose_out;
  std::string compose_captures;
  auto* compose = app.add_subcommand("compose", "what each screen receives at one frame, from the nodes' captures");
  compose->add_option("--config", compose_config, "installation file")->required();
  compose->add_option("--frame", compose_frame_number, "a captured frame number")->required();
  compose->add_option("--out", compose_out, "writes OUT/screens/<screen-id>/frame-NNNNNN.exr and .png")->required();
  compose->add_option("--captures", compose_captures,
                      "folder with <projector-id>/frame-NNNNNN.png (default: OUT/nodes, where --local runs put them)");

  CalibrateOptions calibrate_options;
  auto* calibrate_command =
      app.add_subcommand("calibrate", "fit a projector's homography (screen → pixels) from measured points");
  calibrate_command
      ->add_option("--points", calibrate_options.points_path, "points file (JSON: pixel ↔ screen or tracker)")
      ->required();
  calibrate_command->add_option("--out", calibrate_options.out_path, "calibration file to write (JSON)")->required();
  calibrate_command->add_flag("--robust", calibrate_options.robust, "RANSAC: leave gross outliers out of the fit");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? kExitOk : kExitUsage;
  }

  if (check->parsed()) return check_config(check_files);
  if (calibrate_command->parsed()) return calibrate(calibrate_options, std::cout, std::cerr);
  if (compose->parsed()) {
    auto loaded = config::load_installation(compose_config);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      return kExitUsage;
    }
    auto logger = log::make_logger("master", log_level);
    const std::string captures = compose_captures.empty() ? compose_out + "/nodes" : compose_captures;
    if (auto composed = compose_frame(loaded.value(), compose_frame_number, captures, compose_out, *logger);
        !composed) {
      logger->error("{}", composed.error());
      return kExitUsage;
    }
    return kExitOk;
  }
  if (reference->parsed()) {
    auto loaded = load_config_and_scene(reference_config);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      return kExitUsage;
    }
    auto logger = log::make_logger("master", log_level);
    if (auto done = render_reference(loaded.value().first, loaded.value().second, reference_frame, reference_out,
                                     *logger, reference_options);
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
  auto secret = load_installation_secret(options.config);
  if (!secret) {
    std::cerr << config::describe_problems({{"master.secret_file", secret.error()}}, config_path) << "\n";
    return kExitUsage;
  }
  options.secret = std::move(secret).value();
  options.secret_path = secret_path(options.config);
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
  // A --local run that captured frames also shows what the screens received.
  const bool local_captures = options.local && options.capture_every != 0;
  const config::LoadedConfig config_for_composites = options.config;
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
  const int status = master.exit_code();
  if (status == kExitOk && local_captures) compose_local_captures(config_for_composites, out_dir, *logger);
  return status;
}

}  // namespace optique::master
