#include "config/validate.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "config/address.h"
#include "config/color_fields.h"
#include "config/defaults.h"
#include "config/light_list.h"
#include "config/names.h"
#include "config/response.h"
#include "config/tracking.h"
#include "config/up_conversion.h"
#include "scene/builtin.h"
#include "util/join.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

// A screen without an id is already an error of its own; a reference to a
// screen then cannot be judged, and "unknown screen" would only add noise.
bool every_screen_named(const schema::Installation& inst) {
  for (const schema::Screen& s : inst.screens()) {
    if (s.id().empty()) return false;
  }
  return true;
}

using util::number_text;

class Checker {
 public:
  explicit Checker(std::vector<Problem>& problems) : problems_(problems) {}

  void fail(const std::string& path, const std::string& message) { problems_.push_back({path, message}); }
  [[nodiscard]] std::vector<Problem>& problems() { return problems_; }

  bool finite(const std::string& path, double v) {
    if (std::isfinite(v)) return true;
    fail(path, "must be a finite number (got " + number_text(v) + ")");
    return false;
  }

  void positive(const std::string& path, double v) {
    if (finite(path, v) && v <= 0.0) fail(path, "must be > 0 (got " + number_text(v) + ")");
  }

  void non_negative(const std::string& path, double v) {
    if (finite(path, v) && v < 0.0) fail(path, "must be >= 0 (got " + number_text(v) + ")");
  }

  // A 3-vector of finite numbers; returns whether it is one.
  bool vec3(const std::string& path, const google::protobuf::RepeatedField<double>& v) {
    if (v.size() != 3) {
      fail(path, "must be [x, y, z] (got " + std::to_string(v.size()) + " numbers)");
      return false;
    }
    bool ok = true;
    for (int i = 0; i < 3; ++i) ok = finite(path + "[" + std::to_string(i) + "]", v[i]) && ok;
    return ok;
  }

  // A name of `table` (config/names.h), or empty: the default applies.
  template <class E, std::size_t N>
  void one_of(const std::string& path, const std::string& value, const std::array<Named<E>, N>& table) {
    if (from_name(table, value)) return;
    fail(path, "unknown value '" + value + "' (expected one of: " + util::joined(names_of(table)) + ")");
  }

 private:
  std::vector<Problem>& problems_;
};

bool usable_as_file_name(const std::string& id) {
  if (id.empty() || id == "." || id == "..") return false;
  for (char c : id) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
    if (!ok) return false;
  }
  return true;
}

void check_id(Checker& check, const std::string& path, const std::string& id, std::set<std::string>& seen,
              const char* what) {
  if (id.empty()) {
    check.fail(path, std::string("every ") + what + " needs an id");
  } else if (!usable_as_file_name(id)) {
    check.fail(path, "id '" + id + "' may only use letters, digits, '-', '_' and '.' (it names output folders)");
  } else if (!seen.insert(id).second) {
    check.fail(path, std::string("duplicate ") + what + " id '" + id + "'");
  }
}

double dot(const google::protobuf::RepeatedField<double>& a, const google::protobuf::RepeatedField<double>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void check_screens(Checker& check, const schema::Installation& inst, std::set<std::string>& ids) {
  if (inst.screens().empty()) check.fail("screens", "at least one screen is needed");
  for (int i = 0; i < inst.screens_size(); ++i) {
    const schema::Screen& s = inst.screens(i);
    const std::string at = "screens[" + std::to_string(i) + "]";
    check_id(check, at + ".id", s.id(), ids, "screen");
    check.vec3(at + ".origin", s.origin());
    const bool right_ok = check.vec3(at + ".right", s.right());
    const bool up_ok = check.vec3(at + ".up", s.up());
    constexpr double kTolerance = 1e-3;
    if (right_ok && std::abs(std::sqrt(dot(s.right(), s.right())) - 1.0) > kTolerance) {
      check.fail(at + ".right",
                 "must be a unit vector (length " + number_text(std::sqrt(dot(s.right(), s.right()))) + ")");
    }
    if (up_ok && std::abs(std::sqrt(dot(s.up(), s.up())) - 1.0) > kTolerance) {
      check.fail(at + ".up", "must be a unit vector (length " + number_text(std::sqrt(dot(s.up(), s.up()))) + ")");
    }
    if (right_ok && up_ok && std::abs(dot(s.right(), s.up())) > kTolerance) {
      check.fail(at + ".up",
                 "must be perpendicular to right (dot product " + number_text(dot(s.right(), s.up())) + ")");
    }
    check.positive(at + ".width", s.width());
    check.positive(at + ".height", s.height());
    check.non_negative(at + ".pixels_per_metre", s.pixels_per_metre());
  }
}

void check_region(Checker& check, const std::string& at, const schema::Region& r, const schema::Screen* screen) {
  check.non_negative(at + ".x", r.x());
  check.non_negative(at + ".y", r.y());
  check.positive(at + ".width", r.width());
  check.positive(at + ".height", r.height());
  if (screen == nullptr) return;
  constexpr double kSlack = 1e-9;
  if (std::isfinite(r.x() + r.width()) && r.x() + r.width() > screen->width() + kSlack) {
    check.fail(at, "extends past the right edge of screen '" + screen->id() + "' (x + width = " +
                       number_text(r.x() + r.width()) + " m > " + number_text(screen->width()) + " m)");
  }
  if (std::isfinite(r.y() + r.height()) && r.y() + r.height() > screen->height() + kSlack) {
    check.fail(at, "extends past the top edge of screen '" + screen->id() + "' (y + height = " +
                       number_text(r.y() + r.height()) + " m > " + number_text(screen->height()) + " m)");
  }
}

// Nine finite numbers, row-major 3×3.
void check_matrix3(Checker& check, const std::string& path, const google::protobuf::RepeatedField<double>& m) {
  if (m.size() != 9) {
    check.fail(path, "must be 9 numbers, the 3×3 matrix row by row (got " + std::to_string(m.size()) + ")");
    return;
  }
  for (int i = 0; i < 9; ++i) check.finite(path + "[" + std::to_string(i) + "]", m[i]);
}

// At most one way to say where the projector's pixels land (a camera view may
// accompany a direct one: it then relates partners to this projector).
void check_geometry_source(Checker& check, const std::string& at, const schema::Projector& p,
                           const std::string& config_dir) {
  if (!p.homography().empty() && !p.calibration().empty()) {
    check.fail(at, "give either homography or calibration, not both");
  }
  if (p.has_region() && (!p.calibration().empty() || p.has_camera() || !p.homography().empty())) {
    check.fail(at + ".region", "a projector with a homography, calibration or camera view takes no region");
  }
  if (!p.homography().empty()) check_matrix3(check, at + ".homography", p.homography());
  if (!p.calibration().empty()) {
    const std::filesystem::path file = std::filesystem::path(config_dir) / p.calibration();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) check.fail(at + ".calibration", "no such file: " + file.string());
  }
  if (p.has_camera()) {
    if (p.camera().camera().empty()) check.fail(at + ".camera.camera", "name the camera (partners share the name)");
    check_matrix3(check, at + ".camera.homography", p.camera().homography());
  }
}

void check_content(Checker& check, const std::string& at, const schema::Content& c) {
  check.one_of(at + ".role", c.role(), kContentRoleNames);
  const std::optional<ContentRole> role = from_name(kContentRoleNames, c.role());
  const bool lights = role == ContentRole::lights;
  if (lights && c.lights().empty()) {
    check.fail(at + ".lights",
               "role 'lights' needs its lights: indices and ranges of the scene's lights (\"0-6\", "
               "\"0, 3, 7-9\") or \"auto\"");
  }
  if (lights && !c.lights().empty() && c.lights() != "auto") {
    if (auto list = parse_light_list(c.lights()); !list) check.fail(at + ".lights", list.error());
  }
  if (!lights && !c.lights().empty()) check.fail(at + ".lights", "only a projector of role 'lights' takes lights");
  if (!lights && c.ambient()) check.fail(at + ".ambient", "only a projector of role 'lights' takes ambient");
  check.non_negative(at + ".blur_radius", c.blur_radius());
  if (role != ContentRole::defocus && c.blur_radius() != 0.0) {
    check.fail(at + ".blur_radius", "only a projector of role 'defocus' has a blur radius");
  }
}

// A defocus projector shows only the blurred share of the image: without a focus
// partner on the same screen for the same eye, the sharp share is missing, and
// the other way round.
void check_stacked_pairs(Checker& check, const schema::Installation& inst) {
  for (int i = 0; i < inst.projectors_size(); ++i) {
    const schema::Projector& p = inst.projectors(i);
    const std::optional<ContentRole> role = from_name(kContentRoleNames, p.content().role());
    if (role != ContentRole::focus && role != ContentRole::defocus) continue;
    const ContentRole wanted = role == ContentRole::focus ? ContentRole::defocus : ContentRole::focus;
    bool partnered = false;
    for (const schema::Projector& other : inst.projectors()) {
      partnered = partnered ||
                  (from_name(kContentRoleNames, other.content().role()) == wanted && other.screen() == p.screen() &&
                   from_name(kEyeNames, other.eye()) == from_name(kEyeNames, p.eye()));
    }
    if (!partnered) {
      check.fail("projectors[" + std::to_string(i) + "].content.role",
                 "a '" + std::string(to_string(*role)) + "' projector needs a '" + std::string(to_string(wanted)) +
                     "' partner on screen '" + p.screen() + "' for the same eye, and '" + p.id() +
                     "' has none: the pair shows depth of field together");
    }
  }
}

void check_depth_range(Checker& check, const schema::DepthOfField& d) {
  check.non_negative("depth_of_field.near", d.near());
  check.non_negative("depth_of_field.far", d.far());
  if (d.near() != 0.0 && d.far() != 0.0 && std::isfinite(d.near()) && std::isfinite(d.far()) && !(d.far() > d.near())) {
    check.fail("depth_of_field.far",
               "must be greater than near (" + number_text(d.far()) + " m <= " + number_text(d.near()) + " m)");
  }
  check.non_negative("depth_of_field.inset_radius", d.inset_radius());
}

void check_depth_of_field(Checker& check, const schema::Installation& inst) {
  bool needed = false;
  for (const schema::Projector& p : inst.projectors()) {
    const std::optional<ContentRole> role = from_name(kContentRoleNames, p.content().role());
    needed = needed || role == ContentRole::focus || role == ContentRole::defocus;
  }
  const schema::DepthOfField& d = inst.depth_of_field();
  const bool given = inst.has_depth_of_field();
  if (!needed) {
    if (given) check.fail("depth_of_field", "set, but no projector has role 'focus' or 'defocus'");
    return;
  }
  const int sources = (d.focal_depth() != 0.0 ? 1 : 0) + (d.focal_path().empty() ? 0 : 1) + (d.has_gaze() ? 1 : 0);
  if (sources != 1) {
    check.fail("depth_of_field", sources == 0 ? "focus/defocus projectors need the focal depth: give focal_depth, "
                                                "focal_path or gaze"
                                              : "give only one of focal_depth, focal_path and gaze");
  }
  if (d.focal_depth() != 0.0) check.positive("depth_of_field.focal_depth", d.focal_depth());
  for (int i = 0; i < d.focal_path_size(); ++i) {
    const std::string at = "depth_of_field.focal_path[" + std::to_string(i) + "]";
    check.non_negative(at + ".time", d.focal_path(i).time());
    check.positive(at + ".depth", d.focal_path(i).depth());
    if (i > 0 && !(d.focal_path(i).time() > d.focal_path(i - 1).time())) {
      check.fail(at + ".time", "times must increase (" + number_text(d.focal_path(i).time()) + " after " +
                                   number_text(d.focal_path(i - 1).time()) + ")");
    }
  }
  if (d.has_gaze()) {
    const schema::Gaze& g = d.gaze();
    const schema::Screen* screen = nullptr;
    for (const schema::Screen& s : inst.screens()) {
      if (s.id() == g.screen()) screen = &s;
    }
    if (screen == nullptr && every_screen_named(inst)) {
      check.fail("depth_of_field.gaze.screen", "unknown screen '" + g.screen() + "'");
    }
    if (g.point().empty() == g.path().empty()) {
      check.fail("depth_of_field.gaze", "give either point [x, y] or a path of points");
    }
    const auto check_point = [&](const std::string& path, const google::protobuf::RepeatedField<double>& point) {
      if (point.size() != 2) {
        check.fail(path, "must be [x, y] in metres on the screen (got " + std::to_string(point.size()) + " numbers)");
        return;
      }
      if (!check.finite(path + "[0]", point[0]) || !check.finite(path + "[1]", point[1]) || screen == nullptr) return;
      if (point[0] < 0.0 || point[0] > screen->width() || point[1] < 0.0 || point[1] > screen->height()) {
        check.fail(path, "[" + number_text(point[0]) + ", " + number_text(point[1]) + "] is off screen '" +
                             screen->id() + "' (" + number_text(screen->width()) + " × " +
                             number_text(screen->height()) + " m)");
      }
    };
    if (!g.point().empty()) check_point("depth_of_field.gaze.point", g.point());
    for (int i = 0; i < g.path_size(); ++i) {
      const std::string at = "depth_of_field.gaze.path[" + std::to_string(i) + "]";
      check.non_negative(at + ".time", g.path(i).time());
      check_point(at + ".point", g.path(i).point());
      if (i > 0 && !(g.path(i).time() > g.path(i - 1).time())) {
        check.fail(at + ".time", "times must increase (" + number_text(g.path(i).time()) + " after " +
                                     number_text(g.path(i - 1).time()) + ")");
      }
    }
  }
  check_depth_range(check, d);
  if (d.inset_radius() > 0.0 && !d.has_gaze()) {
    check.fail("depth_of_field.inset_radius", "the focused inset follows the gaze point: give gaze too");
  }
}

void check_projectors(Checker& check, const schema::Installation& inst, const std::string& config_dir, Scope scope,
                      CheckedSections& sections) {
  if (inst.projectors().empty()) check.fail("projectors", "at least one projector is needed");
  std::set<std::string> ids;
  constexpr std::uint32_t kMaxPixels = 16384;
  for (int i = 0; i < inst.projectors_size(); ++i) {
    const schema::Projector& p = inst.projectors(i);
    const std::string at = "projectors[" + std::to_string(i) + "]";
    check_id(check, at + ".id", p.id(), ids, "projector");
    if (p.width() == 0 || p.width() > kMaxPixels) {
      check.fail(at + ".width",
                 "must be 1.." + std::to_string(kMaxPixels) + " pixels (got " + std::to_string(p.width()) + ")");
    }
    if (p.height() == 0 || p.height() > kMaxPixels) {
      check.fail(at + ".height",
                 "must be 1.." + std::to_string(kMaxPixels) + " pixels (got " + std::to_string(p.height()) + ")");
    }
    const schema::Screen* screen = nullptr;
    for (const schema::Screen& s : inst.screens()) {
      if (s.id() == p.screen()) screen = &s;
    }
    if (p.screen().empty()) {
      check.fail(at + ".screen", "must name the screen this projector lights");
    } else if (screen == nullptr && every_screen_named(inst)) {
      const std::string known = util::joined(inst.screens(), [](const schema::Screen& s) { return s.id(); });
      check.fail(at + ".screen", "unknown screen '" + p.screen() + "' (screens are: " + known + ")");
    }
    if (p.has_region()) check_region(check, at + ".region", p.region(), screen);
    check_geometry_source(check, at, p, config_dir);
    check.one_of(at + ".output.kind", p.output().kind(), kOutputKindNames);
    check.one_of(at + ".eye", p.eye(), kEyeNames);
    check.one_of(at + ".rendering", p.rendering(), kRenderMethodNames);
    check.non_negative(at + ".blend_ramp", p.blend_ramp());
    if (auto model = parse_response(p); !model) {
      // The model's messages start with the field ("response.table[3]: …").
      const std::string& e = model.error();
      const auto colon = e.find(": ");
      check.fail(at + "." + e.substr(0, colon), colon == std::string::npos ? e : e.substr(colon + 2));
      sections.responses.emplace_back();
    } else {
      sections.responses.push_back(std::move(model).value());
    }
    check_content(check, at + ".content", p.content());
    const std::size_t problems_before = check.problems().size();
    ColorFields fields;
    UpConversion up;
    if (p.has_color_fields()) fields = parse_color_fields(p.color_fields(), at + ".color_fields", check.problems());
    if (p.has_up_conversion()) up = parse_up_conversion(p.up_conversion(), at + ".up_conversion", check.problems());
    if (check.problems().size() == problems_before) {  // each well formed: together?
      if (auto problem = up_conversion_with_fields(up, fields)) check.fail(at + "." + problem->path, problem->message);
    }
    sections.color_fields.push_back(fields);
    sections.up_conversion.push_back(up);
    // A preset's field times are shares of its projector's frame: at another
    // frame rate every field would last longer or shorter than the projector's.
    const double rate = inst.master().frame_rate() > 0.0 ? inst.master().frame_rate() : defaults::kFrameRate;
    if (p.has_color_fields() && !p.color_fields().preset().empty() && fields.method != FieldMethod::off) {
      if (const auto preset_rate = preset_frame_rate(p.color_fields().preset());
          preset_rate && std::abs(*preset_rate - rate) > 0.01) {
        check.fail(at + ".color_fields.preset",
                   "'" + p.color_fields().preset() + "' is the field timing of a " + number_text(*preset_rate) +
                       " Hz projector, but master.frame_rate is " + number_text(rate) + " Hz: each field would last " +
                       number_text(*preset_rate / rate) + " times as long (set master.frame_rate, or give the fields)");
      }
    }
    // Interpolation draws key frames from the scene sent ahead; a live tracked
    // head cannot be sent ahead, only predicted that far.
    if (p.has_up_conversion() && up.enabled() && up.mode == UpMode::interpolate && inst.viewer().has_tracking() &&
        inst.viewer().tracking().source() != "replay") {
      check.fail(at + ".up_conversion.mode",
                 "interpolate draws key frames from the scene ratio − 1 frames ahead, but the head is tracked live "
                 "(viewer.tracking): it cannot be known ahead; use extrapolate");
    }
  }
  if (scope == Scope::installation) check_stacked_pairs(check, inst);
}

void check_viewer(Checker& check, const schema::Viewer& v, CheckedSections& sections) {
  const bool has_eye = !v.eye().empty();
  const bool has_path = !v.path().empty();
  if (has_eye == has_path) {
    check.fail("viewer",
               has_eye ? "give either eye or path, not both" : "give the eye position: eye [x, y, z] or a path");
  }
  if (has_eye) check.vec3("viewer.eye", v.eye());
  for (int i = 0; i < v.path_size(); ++i) {
    const std::string at = "viewer.path[" + std::to_string(i) + "]";
    check.non_negative(at + ".time", v.path(i).time());
    check.vec3(at + ".position", v.path(i).position());
    if (i > 0 && !(v.path(i).time() > v.path(i - 1).time())) {
      check.fail(at + ".time", "times must increase (" + number_text(v.path(i).time()) + " after " +
                                   number_text(v.path(i - 1).time()) + ")");
    }
  }
  check.non_negative("viewer.eye_separation", v.eye_separation());
  check.non_negative("viewer.near", v.near());
  check.non_negative("viewer.far", v.far());
  const double near = v.near() != 0.0 ? v.near() : defaults::kNear;
  const double far = v.far() != 0.0 ? v.far() : defaults::kFar;
  if (std::isfinite(near) && std::isfinite(far) && near >= 0.0 && far >= 0.0 && !(far > near)) {
    check.fail("viewer.far", "must be greater than near (" + number_text(far) + " m <= " + number_text(near) + " m)");
  }
  if (!v.head_right().empty() && check.vec3("viewer.head_right", v.head_right()) &&
      std::abs(std::sqrt(dot(v.head_right(), v.head_right())) - 1.0) > 1e-3) {
    check.fail("viewer.head_right",
               "must be a unit vector (length " + number_text(std::sqrt(dot(v.head_right(), v.head_right()))) + ")");
  }
  if (v.eye_separation() > 1.0)
    check.fail("viewer.eye_separation",
               "is in metres; " + number_text(v.eye_separation()) + " m is not an eye separation");
  if (v.has_tracking()) sections.tracking = parse_tracking(v.tracking(), "viewer.tracking", check.problems());
}

void check_master(Checker& check, const schema::MasterSettings& m) {
  if (!m.listen().empty()) {
    if (!is_ip_address(m.listen())) {
      check.fail("master.listen", "'" + m.listen() + "' is not an IPv4 or IPv6 address");
    }
  }
  if (m.port() > 65535) check.fail("master.port", "must be 0..65535 (got " + std::to_string(m.port()) + ")");
  if (check.finite("master.frame_rate", m.frame_rate()) && (m.frame_rate() < 0.0 || m.frame_rate() > 1000.0)) {
    check.fail("master.frame_rate",
               "must be in (0, 1000] Hz, or 0 for the default (got " + number_text(m.frame_rate()) + ")");
  }
  if (!from_name(kStragglerPolicyNames, m.straggler_policy())) {
    check.fail("master.straggler_policy", "unknown policy '" + m.straggler_policy() +
                                              "' (\"present\": the frame without the late node, or "
                                              "\"drop\": the frame everywhere)");
  }
  if (m.has_min_presented() && check.finite("master.min_presented", m.min_presented()) &&
      (m.min_presented() < 0.0 || m.min_presented() > 1.0)) {
    check.fail("master.min_presented",
               "is a share of the frames, 0 to 1 (got " + number_text(m.min_presented()) + "; 0.9 means 90 %)");
  }
  if (m.max_message_bytes() != 0 && m.max_message_bytes() < 1024) {
    check.fail("master.max_message_bytes", "must be at least 1024 (got " + std::to_string(m.max_message_bytes()) + ")");
  }
  if (m.has_status()) {
    const schema::StatusServer& st = m.status();
    if (!st.listen().empty() && !is_ip_address(st.listen())) {
      check.fail("master.status.listen", "'" + st.listen() + "' is not an IPv4 or IPv6 address");
    } else if (!st.listen().empty() && !is_loopback_address(st.listen()) && m.secret_file().empty()) {
      check.fail("master.status.listen",
                 "'" + st.listen() +
                     "' is reached from other machines, so the status needs a bearer token, derived from the "
                     "shared secret: set master.secret_file (or listen on 127.0.0.1)");
    }
    if (st.port() > 65535) check.fail("master.status.port", "must be 0..65535 (got " + std::to_string(st.port()) + ")");
    if (st.max_connections() > 100000) {
      check.fail("master.status.max_connections",
                 "must be at most 100000 (got " + std::to_string(st.max_connections()) + ")");
    }
  }
  const std::uint32_t heartbeat = m.heartbeat_ms() != 0 ? m.heartbeat_ms() : defaults::kHeartbeatMs;
  if (m.liveness_timeout_ms() != 0 && m.liveness_timeout_ms() <= 2 * heartbeat) {
    check.fail("master.liveness_timeout_ms", "must be more than twice heartbeat_ms (" + std::to_string(heartbeat) +
                                                 " ms), or peers are dropped between heartbeats");
  }
}

// Switch times in order, lists that parse, and no switch that changes nothing (a
// light switched off while off, or on while on). Whether the scene has those
// lights is checked once it is loaded.
void check_light_switches(Checker& check, const schema::Scene& scene) {
  // What each switch changes depends on the ones before it in time: out of
  // order, "light 3 is not off" would blame the wrong switch. Then only the
  // order is reported.
  bool in_order = true;
  for (int i = 1; i < scene.light_switches_size(); ++i) {
    if (scene.light_switches(i).time() < scene.light_switches(i - 1).time()) in_order = false;
  }
  std::set<std::uint32_t> off;
  double previous_time = 0.0;
  for (int i = 0; i < scene.light_switches_size(); ++i) {
    const schema::LightSwitch& entry = scene.light_switches(i);
    const std::string path = "scene.light_switches[" + std::to_string(i) + "]";
    if (!std::isfinite(entry.time()) || entry.time() < 0.0) {
      check.fail(path + ".time", "must be a finite number of seconds ≥ 0 (got " + number_text(entry.time()) + ")");
    } else if (entry.time() < previous_time) {
      check.fail(path + ".time", "switches must be in time order: " + number_text(entry.time()) +
                                     " s comes before the switch above it at " + number_text(previous_time) + " s");
    } else {
      previous_time = entry.time();
    }
    if (entry.off().empty() && entry.on().empty()) {
      check.fail(path, "switches nothing: give the lights that go \"off\" or come \"on\"");
    }
    auto going_off = parse_light_list(entry.off());
    if (!going_off) check.fail(path + ".off", going_off.error());
    auto coming_on = parse_light_list(entry.on());
    if (!coming_on) check.fail(path + ".on", coming_on.error());
    if (!going_off || !coming_on || !in_order) continue;
    std::vector<std::uint32_t> already_off;
    for (std::uint32_t light : going_off.value()) {
      if (!off.insert(light).second) already_off.push_back(light);
    }
    if (!already_off.empty()) {
      check.fail(path + ".off", "light " + format_light_list(already_off) +
                                    " is off already: a switch that changes nothing is probably a typo");
    }
    std::vector<std::uint32_t> not_off;
    for (std::uint32_t light : coming_on.value()) {
      const bool switched_off_here =
          std::find(going_off.value().begin(), going_off.value().end(), light) != going_off.value().end();
      if (switched_off_here || off.erase(light) == 0) not_off.push_back(light);
    }
    if (!not_off.empty()) {
      check.fail(path + ".on", "light " + format_light_list(not_off) +
                                   " is not off: a switch that changes nothing is probably a typo");
    }
  }
}

void check_scene(Checker& check, const schema::Scene& s, const std::string& config_dir, Scope scope) {
  const bool builtin = !s.builtin().empty();
  const bool gltf = !s.gltf().empty();
  if (builtin == gltf) {
    check.fail("scene", builtin ? "give either builtin or gltf, not both" : "name a builtin scene or a gltf file");
    return;
  }
  if (builtin && !scene::is_builtin_scene(s.builtin())) {
    check.fail("scene.builtin", "unknown scene '" + s.builtin() +
                                    "' (built-in scenes are: " + util::joined(scene::builtin_scene_names()) + ")");
  }
  check_light_switches(check, s);
  if (gltf && scope == Scope::installation) {
    const std::filesystem::path file = std::filesystem::path(config_dir) / s.gltf();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) check.fail("scene.gltf", "no such file: " + file.string());
  }
}

}  // namespace

std::string describe_problems(const std::vector<Problem>& problems, const std::string& origin) {
  std::string message;
  for (const Problem& p : problems)
    message += (message.empty() ? "" : "\n") + origin + ": " + p.path + ": " + p.message;
  return message;
}

std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir, Scope scope) {
  CheckedSections ignored;
  return validate(installation, config_dir, scope, ignored);
}

std::vector<Problem> validate(const schema::Installation& installation, const std::string& config_dir, Scope scope,
                              CheckedSections& sections) {
  sections = {};
  std::vector<Problem> problems;
  Checker check(problems);
  std::set<std::string> screen_ids;
  check_screens(check, installation, screen_ids);
  check_projectors(check, installation, config_dir, scope, sections);
  check_viewer(check, installation.viewer(), sections);
  check_master(check, installation.master());
  check_scene(check, installation.scene(), config_dir, scope);
  if (scope == Scope::installation) {
    check_depth_of_field(check, installation);
  } else if (installation.has_depth_of_field()) {
    check_depth_range(check, installation.depth_of_field());
  }
  return problems;
}

}  // namespace optique::config
