#include "config/parse.h"

#include "config/sections.h"

namespace optique::config {
namespace {

// The sections in order, then what relates them; the homographies last, as
// they need every projector's screen and partner to be right.
Installation build(const schema::Installation& inst, const std::string& config_dir, Scope scope,
                   std::vector<Problem>& problems) {
  Checker check(problems);
  Installation out;
  out.name = inst.name();
  out.screens = parse_screens(inst, check);
  out.projectors = parse_projectors(inst, out.screens, config_dir, check);
  out.viewer = parse_viewer(inst.viewer(), config_dir, check);
  out.master = parse_master(inst.master(), config_dir, check);
  out.scene = parse_scene(inst.scene(), config_dir, scope, check);
  out.depth_of_field =
      parse_depth_of_field(inst, out.screens, out.viewer, scope, needs_depth_of_field(out.projectors), check);
  check_across_sections(inst, out, scope, check);
  if (problems.empty()) resolve_homographies(inst, out, config_dir, problems);
  return out;
}

Result<Installation> parse(const schema::Installation& inst, const std::string& config_dir, const std::string& origin,
                           Scope scope) {
  std::vector<Problem> problems;
  Installation out = build(inst, config_dir, scope, problems);
  if (!problems.empty()) return Error{describe_problems(problems, origin)};
  return out;
}

}  // namespace

std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir, Scope scope) {
  std::vector<Problem> problems;
  (void)build(installation, config_dir, scope, problems);
  return problems;
}

Result<Installation> parse_installation(const schema::Installation& installation, const std::string& config_dir,
                                        const std::string& origin) {
  return parse(installation, config_dir, origin, Scope::installation);
}

Result<ProjectorJob> parse_job(const schema::Installation& job, std::string_view projector_id,
                               const std::string& origin) {
  if (job.screens_size() != 1) {
    return Error{origin + ": a projector's job names one screen (got " + std::to_string(job.screens_size()) + ")"};
  }
  // Paths in a job are absolute already: the master resolved them.
  auto built = parse(job, "/", origin, Scope::job);
  if (!built) return Error{built.error()};
  const auto self = built.value().find_projector(projector_id);
  if (!self) {
    return Error{origin + ": projector '" + std::string(projector_id) + "' is not among the projectors of its job"};
  }
  return ProjectorJob{std::move(built).value(), *self};
}

}  // namespace optique::config
