#include "tools/cli.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include "image/texture_decode.h"
#include "log/logger.h"
#include "master/run/exit_codes.h"
#include "master/run/run_config.h"
#include "tools/calibrate.h"
#include "tools/check_config.h"
#include "tools/compose.h"
#include "tools/perceive.h"
#include "tools/render_reference.h"
#include "util/join.h"

namespace optique::tools {
namespace {

using master::kExitFailed;
using master::kExitOk;
using master::kExitUsage;

// The tools draw scenes or check them as the nodes will: with their images.
Result<master::RunConfig> load_with_images(const std::string& path) {
  return master::load_run_config(path, image::decode_texture);
}

int check_config(const std::vector<std::string>& files) {
  int status = kExitOk;
  for (const auto& file : files) {
    auto loaded = load_with_images(file);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      status = kExitUsage;
      continue;
    }
    std::cout << summarize(loaded.value().config);
    const scene::LoadedScene& scene = loaded.value().scene;
    if (!scene.manifest.files.empty()) {
      const std::string names = util::joined(scene.manifest.files, [](const auto& f) { return f.path; });
      std::cout << "  scene files: " << scene.manifest.files.size() << " (" << names << "), "
                << fmt::format("{:.1f}", static_cast<double>(scene.manifest.total_bytes()) / (1 << 20))
                << " MiB, identity " << scene.content_sha256.substr(0, 12)
                << "…: sent to every node that has no copy\n";
    }
    for (const auto& warning : scene.warnings) std::cout << "  scene warning: " << warning << "\n";
    for (const auto& note : scene.notes) std::cout << "  scene: " << note << "\n";
  }
  return status;
}

// The frames that the first projector captured, in order (compose skips, with a
// warning, a frame that another node missed).
std::vector<std::uint64_t> captured_frames(const config::LoadedConfig& config, const std::string& captures) {
  std::vector<std::uint64_t> frames;
  const auto& projectors = config.installation.projectors;
  if (projectors.empty()) return frames;
  std::error_code ec;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(captures) / projectors.front().id, ec)) {
    const std::string name = entry.path().filename().string();
    std::uint64_t frame = 0;
    // The signal captures, which compose reads (the .exr beside them is not needed).
    if (std::sscanf(name.c_str(), "frame-%" SCNu64 ".png", &frame) == 1 && name.ends_with(".png")) {
      frames.push_back(frame);
    }
  }
  std::sort(frames.begin(), frames.end());
  return frames;
}

}  // namespace

int run_cli(int argc, char** argv) {
  CLI::App app{"optique-tools: check, compose, render and calibrate what optique-master runs"};
  app.require_subcommand(1);
  std::string log_level = "info";
  std::string log_file;
  app.add_option("--log-level", log_level, "trace, debug, info, warn or error")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
  app.add_option("--log-file", log_file, "also append the log to this file")->group("");

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
  std::string reference_replay;
  reference->add_option("--replay", reference_replay,
                        "a journal the master recorded (--record): draw the live instances its last run shows then");

  std::string compose_config;
  std::uint64_t compose_frame_number = 0;
  bool compose_all = false;
  std::string compose_out;
  std::string compose_captures;
  auto* compose = app.add_subcommand("compose", "what each screen receives at one frame, from the nodes' captures");
  compose->add_option("--config", compose_config, "installation file")->required();
  auto* frame_option = compose->add_option("--frame", compose_frame_number, "a captured frame number");
  compose->add_flag("--every-captured-frame", compose_all, "every frame the first projector captured")
      ->excludes(frame_option);
  compose->add_option("--out", compose_out, "writes OUT/screens/<screen-id>/frame-NNNNNN.exr and .png")->required();
  compose->add_option("--captures", compose_captures,
                      "folder with <projector-id>/frame-NNNNNN.png (default: OUT/nodes, where --local runs put them)");

  std::string perceive_config;
  std::string perceive_out;
  std::string perceive_track;
  PerceiveOptions perceive_options;
  auto* perceive_command = app.add_subcommand(
      "perceive", "what an eye that follows motion sees on each screen around one frame, colour fields and all");
  perceive_command->add_option("--config", perceive_config, "installation file")->required();
  perceive_command->add_option("--frame", perceive_options.frame,
                               "the exposure is centred on this frame's display time");
  perceive_command
      ->add_option("--track", perceive_track,
                   "what the eye follows: a scene object's name, or vx,vy in screen pixels per frame (y down)")
      ->required();
  perceive_command->add_option("--exposure", perceive_options.exposure, "seconds; default one 60 Hz frame");
  perceive_command->add_option("--out", perceive_out, "writes OUT/perceived/<screen>/ and <screen>.ideal/")->required();

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
    if (compose->parsed() && frame_option->count() == 0 && !compose_all) {
      throw CLI::RequiredError("compose needs --frame K or --every-captured-frame");
    }
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? kExitOk : kExitUsage;
  }

  if (check->parsed()) return check_config(check_files);
  if (perceive_command->parsed()) {
    if (auto track = parse_track(perceive_track, perceive_options); !track) {
      std::cerr << track.error() << "\n";
      return kExitUsage;
    }
    auto loaded = load_with_images(perceive_config);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      return kExitUsage;
    }
    auto logger = log::make_logger("perceive", log_level, log_file, log::FileMode::append);
    auto seen = perceive(loaded.value().config, loaded.value().scene, perceive_options, perceive_out, *logger);
    if (!seen) {
      logger->error("{}", seen.error());
      return kExitUsage;
    }
    return kExitOk;
  }
  if (calibrate_command->parsed()) return calibrate(calibrate_options, std::cout, std::cerr);
  if (compose->parsed()) {
    auto loaded = config::load_installation(compose_config);
    if (!loaded) {
      std::cerr << loaded.error() << "\n";
      return kExitUsage;
    }
    auto logger = log::make_logger("compose", log_level, log_file, log::FileMode::append);
    const std::string captures = compose_captures.empty() ? compose_out + "/nodes" : compose_captures;
    if (compose_all) {
      for (std::uint64_t frame : captured_frames(loaded.value(), captures)) {
        if (auto composed = compose_frame(loaded.value(), frame, captures, compose_out, *logger); !composed) {
          logger->warn("frame {} not composed: {}", frame, composed.error());
        }
      }
      return kExitOk;
    }
    if (auto composed = compose_frame(loaded.value(), compose_frame_number, captures, compose_out, *logger);
        !composed) {
      logger->error("{}", composed.error());
      return kExitUsage;
    }
    return kExitOk;
  }
  // render-reference
  auto loaded = load_with_images(reference_config);
  if (!loaded) {
    std::cerr << loaded.error() << "\n";
    return kExitUsage;
  }
  std::optional<master::Journal> journal;
  if (!reference_replay.empty()) {
    auto read = master::read_journal_file(reference_replay);
    if (!read) {
      std::cerr << "--replay: " << read.error() << "\n";
      return kExitUsage;
    }
    journal = std::move(read).value();
    reference_options.replay = &*journal;
  }
  auto logger = log::make_logger("reference", log_level, log_file, log::FileMode::append);
  if (auto done = render_reference(loaded.value().config, loaded.value().scene, reference_frame, reference_out, *logger,
                                   reference_options);
      !done) {
    logger->error("{}", done.error());
    return kExitFailed;
  }
  return kExitOk;
}

}  // namespace optique::tools
