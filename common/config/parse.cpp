#include "config/parse.h"

#include <algorithm>
#include <cassert>
#include <filesystem>

#include <glm/matrix.hpp>

#include "config/asset_path.h"
#include "config/calibration_file.h"
#include "config/light_list.h"
#include "config/names.h"
#include "config/response.h"

namespace optique::config {
namespace {

// Runs on what validate() accepted: the asserts below hold for such input.

glm::dvec3 vec3(const google::protobuf::RepeatedField<double>& v) {
  assert(v.size() == 3);
  return {v[0], v[1], v[2]};
}

glm::dvec2 vec2(const google::protobuf::RepeatedField<double>& v) {
  assert(v.size() == 2);
  return {v[0], v[1]};
}

glm::dmat3 matrix3(const google::protobuf::RepeatedField<double>& nine) {
  assert(nine.size() == 9);
  return geometry::homography_from_rows(std::span<const double, 9>(nine.data(), 9));
}

// A name validate() accepted.
template <class E, std::size_t N>
E checked_name(const std::array<Named<E>, N>& table, std::string_view name) {
  const std::optional<E> value = from_name(table, name);
  assert(value);
  return value.value_or(table.front().value);
}

template <class T>
T or_default(T value, T fallback) {
  return value == T{} ? fallback : value;
}

std::string path_of(int i) { return "projectors[" + std::to_string(i) + "]"; }

Screen build_screen(const schema::Screen& s) {
  Screen screen;
  screen.id = s.id();
  screen.origin = vec3(s.origin());
  screen.right = glm::normalize(vec3(s.right()));
  screen.up = glm::normalize(vec3(s.up()));
  screen.width = s.width();
  screen.height = s.height();
  screen.pixels_per_metre = or_default(s.pixels_per_metre(), defaults::kPixelsPerMetre);
  return screen;
}

Content build_content(const schema::Content& c) {
  Content content;
  content.role = checked_name(kContentRoleNames, c.role());
  if (content.role == ContentRole::lights) {
    content.automatic = c.lights() == "auto";
    if (!content.automatic) {
      auto lights = parse_light_list(c.lights());
      assert(lights);
      content.lights = lights ? std::move(lights).value() : std::vector<std::uint32_t>{};
    }
    content.ambient = c.ambient();
  }
  if (content.role == ContentRole::defocus) content.blur_radius = or_default(c.blur_radius(), defaults::kBlurRadius);
  return content;
}

// Everything but the geometry, which needs the other projectors (camera views).
Projector build_projector(const schema::Projector& p, const std::vector<Screen>& screens,
                          const CheckedSections& sections, std::size_t index) {
  Projector projector;
  projector.id = p.id();
  projector.host = p.host().empty() ? "localhost" : p.host();
  projector.width = static_cast<int>(p.width());
  projector.height = static_cast<int>(p.height());
  const auto screen = std::find_if(screens.begin(), screens.end(), [&](const Screen& s) { return s.id == p.screen(); });
  assert(screen != screens.end());
  projector.screen = static_cast<std::size_t>(screen - screens.begin());
  projector.eye = checked_name(kEyeNames, p.eye());
  projector.output.kind = checked_name(kOutputKindNames, p.output().kind());
  projector.output.monitor = p.output().monitor();
  projector.output.fullscreen = p.output().fullscreen();
  projector.rendering = checked_name(kRenderMethodNames, p.rendering());
  projector.blend_ramp = p.blend_ramp();
  // Built by the check already.
  projector.response = sections.responses.at(index);
  projector.content = build_content(p.content());
  projector.color_fields = sections.color_fields.at(index);
  projector.up_conversion = sections.up_conversion.at(index);
  if (p.has_camera()) projector.camera = CameraView{p.camera().camera(), matrix3(p.camera().homography())};
  return projector;
}

// Every projector's homography, whichever way its config gave it; then each must
// light part of its screen. Calibration files and direct matrices first: camera
// views relate a projector to a partner that has its own.
void resolve_geometry(const schema::Installation& inst, Installation& out, const std::string& config_dir,
                      std::vector<Problem>& problems) {
  std::vector<bool> known(out.projectors.size(), false);
  for (int i = 0; i < inst.projectors_size(); ++i) {
    const schema::Projector& p = inst.projectors(i);
    Projector& projector = out.projectors[static_cast<std::size_t>(i)];
    const Screen& screen = out.screen_of(projector);
    if (!p.calibration().empty()) {
      projector.geometry_source = GeometrySource::calibration;
      auto h = read_calibration_homography((std::filesystem::path(config_dir) / p.calibration()).string(), p.width(),
                                           p.height());
      if (!h) {
        problems.push_back({path_of(i) + ".calibration", h.error()});
        continue;
      }
      projector.homography = h.value();
    } else if (!p.homography().empty()) {
      projector.geometry_source = GeometrySource::homography;
      projector.homography = matrix3(p.homography());
    } else if (p.has_camera()) {
      projector.geometry_source = GeometrySource::camera;
      continue;  // below, from a partner
    } else {
      projector.geometry_source = p.has_region() ? GeometrySource::region : GeometrySource::whole_screen;
      const geometry::ScreenRect region =
          p.has_region()
              ? geometry::ScreenRect{{p.region().x(), p.region().y()},
                                     {p.region().x() + p.region().width(), p.region().y() + p.region().height()}}
              : screen.area();
      projector.region = region;
      projector.homography = geometry::aligned_homography(region, projector.width, projector.height);
    }
    known[static_cast<std::size_t>(i)] = true;
  }
  for (std::size_t i = 0; i < out.projectors.size(); ++i) {
    Projector& p = out.projectors[i];
    if (p.geometry_source != GeometrySource::camera) continue;
    const auto partner = std::find_if(out.projectors.begin(), out.projectors.end(), [&](const Projector& q) {
      return known[static_cast<std::size_t>(&q - out.projectors.data())] && q.camera &&
             q.camera->camera == p.camera->camera && q.screen == p.screen;
    });
    if (partner == out.projectors.end()) {
      problems.push_back({path_of(static_cast<int>(i)) + ".camera",
                          "no projector on screen '" + out.screen_of(p).id + "' seen by camera '" + p.camera->camera +
                              "' has a homography or calibration to relate this one to"});
      continue;
    }
    // Partner pixels → camera → this projector's pixels.
    p.homography =
        glm::inverse(p.camera->projector_to_camera) * partner->camera->projector_to_camera * partner->homography;
    known[i] = true;
  }
  for (std::size_t i = 0; i < out.projectors.size(); ++i) {
    if (!known[i]) continue;
    const Projector& p = out.projectors[i];
    auto geometry = geometry::ProjectorGeometry::make(p.homography, p.width, p.height);
    if (!geometry) {
      problems.push_back({path_of(static_cast<int>(i)) + ".homography", geometry.error()});
      continue;
    }
    if (auto oblique = geometry::oblique_projection(geometry.value(), out.screen_of(p).area()); !oblique) {
      problems.push_back({path_of(static_cast<int>(i)), oblique.error() + " (screen '" + out.screen_of(p).id + "')"});
    }
  }
}

Viewer build_viewer(const schema::Viewer& v, const std::string& config_dir, const CheckedSections& sections) {
  Viewer viewer;
  if (v.path().empty()) {
    viewer.path.push_back({0.0, vec3(v.eye())});
  } else {
    for (const schema::PathPoint& point : v.path()) viewer.path.push_back({point.time(), vec3(point.position())});
  }
  viewer.eye_separation = or_default(v.eye_separation(), defaults::kEyeSeparation);
  viewer.near = or_default(v.near(), defaults::kNear);
  viewer.far = or_default(v.far(), defaults::kFar);
  if (!v.head_right().empty()) viewer.head_right = glm::normalize(vec3(v.head_right()));
  if (v.has_tracking()) {
    assert(sections.tracking);  // built by the check
    viewer.tracking = sections.tracking;
    if (!viewer.tracking->file.empty()) viewer.tracking->file = resolve_asset(viewer.tracking->file, config_dir);
  }
  return viewer;
}

MasterSettings build_master(const schema::MasterSettings& m) {
  using std::chrono::milliseconds;
  MasterSettings master;
  if (!m.listen().empty()) master.listen = m.listen();
  master.port = static_cast<std::uint16_t>(m.port());
  master.frame_rate = or_default(m.frame_rate(), defaults::kFrameRate);
  master.frame_timeout = milliseconds(or_default(m.frame_timeout_ms(), defaults::kFrameTimeoutMs));
  master.startup_timeout = milliseconds(or_default(m.startup_timeout_ms(), defaults::kStartupTimeoutMs));
  master.handshake_timeout = milliseconds(or_default(m.handshake_timeout_ms(), defaults::kHandshakeTimeoutMs));
  master.heartbeat = milliseconds(or_default(m.heartbeat_ms(), defaults::kHeartbeatMs));
  // Three heartbeats, or the floor if that is longer.
  master.liveness_timeout = milliseconds(
      or_default(m.liveness_timeout_ms(),
                 std::max(defaults::kMinLivenessTimeoutMs, 3 * static_cast<std::uint32_t>(master.heartbeat.count()))));
  master.present_lead = std::chrono::microseconds(or_default(m.present_lead_us(), defaults::kPresentLeadUs));
  master.max_message_bytes = or_default(m.max_message_bytes(), defaults::kMaxMessageBytes);
  master.secret_file = m.secret_file();
  master.max_pending_connections = or_default(m.max_pending_connections(), defaults::kMaxPendingConnections);
  master.straggler_policy = checked_name(kStragglerPolicyNames, m.straggler_policy());
  if (m.has_min_presented()) master.min_presented = m.min_presented();
  if (m.has_status()) {
    const schema::StatusServer& st = m.status();
    StatusServer status;
    if (!st.listen().empty()) status.listen = st.listen();
    if (st.has_port()) status.port = static_cast<std::uint16_t>(st.port());
    status.max_connections = or_default(st.max_connections(), defaults::kStatusMaxConnections);
    master.status = status;
  }
  return master;
}

SceneSource build_scene(const schema::Scene& s, const std::string& config_dir) {
  SceneSource scene;
  scene.builtin = s.builtin();
  if (!s.gltf().empty()) scene.gltf = resolve_asset(s.gltf(), config_dir);
  for (const schema::LightSwitch& entry : s.light_switches()) {
    auto off = parse_light_list(entry.off());
    auto on = parse_light_list(entry.on());
    assert(off && on);
    if (!off || !on) continue;
    scene.light_switches.push_back({entry.time(), std::move(off).value(), std::move(on).value()});
  }
  return scene;
}

std::optional<DepthOfField> build_depth_of_field(const schema::Installation& inst, const Installation& out) {
  if (!inst.has_depth_of_field()) return std::nullopt;
  const schema::DepthOfField& d = inst.depth_of_field();
  DepthOfField dof;
  if (d.focal_depth() != 0.0) dof.focal_depth = d.focal_depth();
  for (const schema::FocusPoint& point : d.focal_path()) dof.focal_path.push_back({point.time(), point.depth()});
  if (d.has_gaze()) {
    const auto screen = std::find_if(out.screens.begin(), out.screens.end(),
                                     [&](const Screen& s) { return s.id == d.gaze().screen(); });
    if (screen != out.screens.end()) {  // a job does not carry the gaze's screen: it has no use for the gaze
      Gaze gaze;
      gaze.screen = static_cast<std::size_t>(screen - out.screens.begin());
      if (!d.gaze().point().empty()) {
        gaze.path.push_back({0.0, vec2(d.gaze().point())});
      } else {
        for (const schema::GazePoint& point : d.gaze().path()) gaze.path.push_back({point.time(), vec2(point.point())});
      }
      dof.gaze = std::move(gaze);
    }
  }
  dof.near = or_default(d.near(), out.viewer.near);
  dof.far = or_default(d.far(), out.viewer.far);
  dof.inset_radius = d.inset_radius();
  return dof;
}

Result<Installation> build(const schema::Installation& inst, const std::string& config_dir, const std::string& origin,
                           Scope scope) {
  CheckedSections sections;
  if (auto problems = validate(inst, config_dir, scope, sections); !problems.empty()) {
    return Error{describe_problems(problems, origin)};
  }
  Installation out;
  out.name = inst.name();
  for (const schema::Screen& s : inst.screens()) out.screens.push_back(build_screen(s));
  for (std::size_t i = 0; i < static_cast<std::size_t>(inst.projectors_size()); ++i) {
    out.projectors.push_back(build_projector(inst.projectors(static_cast<int>(i)), out.screens, sections, i));
  }
  out.viewer = build_viewer(inst.viewer(), config_dir, sections);
  out.master = build_master(inst.master());
  out.scene = build_scene(inst.scene(), config_dir);
  out.depth_of_field = build_depth_of_field(inst, out);
  std::vector<Problem> problems;
  resolve_geometry(inst, out, config_dir, problems);
  if (!problems.empty()) return Error{describe_problems(problems, origin)};
  return out;
}

}  // namespace

Result<Installation> parse_installation(const schema::Installation& installation, const std::string& config_dir,
                                        const std::string& origin) {
  return build(installation, config_dir, origin, Scope::installation);
}

Result<ProjectorJob> parse_job(const schema::Installation& job, std::string_view projector_id,
                               const std::string& origin) {
  if (job.screens_size() != 1) {
    return Error{origin + ": a projector's job names one screen (got " + std::to_string(job.screens_size()) + ")"};
  }
  // Paths in a job are absolute already: the master resolved them.
  auto built = build(job, "/", origin, Scope::job);
  if (!built) return Error{built.error()};
  const auto self = built.value().find_projector(projector_id);
  if (!self) {
    return Error{origin + ": projector '" + std::string(projector_id) + "' is not among the projectors of its job"};
  }
  return ProjectorJob{std::move(built).value(), *self};
}

}  // namespace optique::config
