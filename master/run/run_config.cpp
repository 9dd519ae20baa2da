#include "master/run/run_config.h"
#include "scene_load/installation_scene.h"

#include "master/run/light_switches.h"
#include "master/run/shared_secret.h"
#include "master/run/stacked_groups.h"

namespace optique::master {

Result<RunConfig> load_run_config(const std::string& path, const scene::ImageDecoder& decode) {
  auto loaded = config::load_installation(path);
  if (!loaded) return Error{loaded.error()};
  const config::SceneSource& source = loaded.value().installation.scene;
  auto scene = config::load_scene(loaded.value().installation, decode);
  if (!scene) return Error{path + ": scene: " + scene.error()};
  const std::size_t light_count = scene.value().definition.lights.size();
  auto problems = check_lighting_groups(loaded.value().installation, light_count);
  for (config::Problem& problem : LightSwitches::check(source, light_count)) {
    problems.push_back(std::move(problem));
  }
  if (!problems.empty()) return Error{config::describe_problems(problems, path)};
  // A refused secret file is a config problem: check-config says so too.
  if (auto secret = load_installation_secret(loaded.value()); !secret) {
    return Error{config::describe_problems({{"master.secret_file", secret.error()}}, path)};
  }
  std::vector<tracking::ReplaySample> replay;
  const auto& tracking = loaded.value().installation.viewer.tracking;
  if (tracking && tracking->source == config::TrackingSource::replay) {
    auto samples = tracking::load_replay(tracking->file);
    if (!samples) return Error{config::describe_problems({{"viewer.tracking.file", samples.error()}}, path)};
    replay = std::move(samples).value();
  }
  return RunConfig{std::move(loaded).value(), std::move(scene).value(), std::move(replay)};
}

}  // namespace optique::master
