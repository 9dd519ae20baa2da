// The projectors: each one's pixels, screen, share of the light, response,
// colour fields and up-conversion, and where its geometry comes from.
#include <cmath>
#include <filesystem>

#include "config/light_list.h"
#include "config/response.h"
#include "config/sections.h"
#include "util/number_text.h"

namespace optique::config {
namespace {

using util::number_text;

constexpr std::uint32_t kMaxPixels = 16384;

// Nine finite numbers, row-major 3×3.
std::optional<glm::dmat3> matrix3(Checker& check, const std::string& path,
                                  const google::protobuf::RepeatedField<double>& m) {
  if (m.size() != 9) {
    check.fail(path, "must be 9 numbers, the 3×3 matrix row by row (got " + std::to_string(m.size()) + ")");
    return std::nullopt;
  }
  bool ok = true;
  for (int i = 0; i < 9; ++i) ok = check.finite(path + "[" + std::to_string(i) + "]", m[i]) && ok;
  if (!ok) return std::nullopt;
  return geometry::homography_from_rows(std::span<const double, 9>(m.data(), 9));
}

std::size_t screen_of(Checker& check, const std::string& path, const std::string& id,
                      const std::vector<Screen>& screens) {
  if (const auto screen = find_screen(screens, id)) return *screen;
  if (id.empty()) {
    check.fail(path, "must name the screen this projector lights");
  } else if (every_screen_named(screens)) {
    const std::string known = util::joined(screens, [](const Screen& s) { return s.id; });
    check.fail(path, "unknown screen '" + id + "' (screens are: " + known + ")");
  }
  return screens.size();
}

std::optional<geometry::ScreenRect> region(Checker& check, const std::string& at, const schema::Region& r,
                                           const Screen* screen) {
  const std::size_t before = check.count();
  check.non_negative(at + ".x", r.x());
  check.non_negative(at + ".y", r.y());
  check.positive(at + ".width", r.width());
  check.positive(at + ".height", r.height());
  if (screen != nullptr) {
    constexpr double kSlack = 1e-9;
    if (std::isfinite(r.x() + r.width()) && r.x() + r.width() > screen->width + kSlack) {
      check.fail(at, "extends past the right edge of screen '" + screen->id + "' (x + width = " +
                         number_text(r.x() + r.width()) + " m > " + number_text(screen->width) + " m)");
    }
    if (std::isfinite(r.y() + r.height()) && r.y() + r.height() > screen->height + kSlack) {
      check.fail(at, "extends past the top edge of screen '" + screen->id + "' (y + height = " +
                         number_text(r.y() + r.height()) + " m > " + number_text(screen->height) + " m)");
    }
  }
  if (check.count() != before) return std::nullopt;
  return geometry::ScreenRect{{r.x(), r.y()}, {r.x() + r.width(), r.y() + r.height()}};
}

// At most one way to say where the projector's pixels land (a camera view may
// accompany a direct one: it then relates partners to this projector). The
// homographies of calibration files and camera views come later
// (resolve_homographies).
void geometry_source(Checker& check, const std::string& at, const schema::Projector& p, const Screen* screen,
                     const std::string& config_dir, Projector& projector) {
  const std::optional<geometry::ScreenRect> part =
      p.has_region() ? region(check, at + ".region", p.region(), screen) : std::nullopt;
  if (!p.homography().empty() && !p.calibration().empty()) {
    check.fail(at, "give either homography or calibration, not both");
  }
  if (p.has_region() && (!p.calibration().empty() || p.has_camera() || !p.homography().empty())) {
    check.fail(at + ".region", "a projector with a homography, calibration or camera view takes no region");
  }
  std::optional<glm::dmat3> direct;
  if (!p.homography().empty()) direct = matrix3(check, at + ".homography", p.homography());
  if (!p.calibration().empty()) {
    const std::filesystem::path file = std::filesystem::path(config_dir) / p.calibration();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) check.fail(at + ".calibration", "no such file: " + file.string());
  }
  if (p.has_camera()) {
    if (p.camera().camera().empty()) check.fail(at + ".camera.camera", "name the camera (partners share the name)");
    if (const auto m = matrix3(check, at + ".camera.homography", p.camera().homography())) {
      projector.camera = CameraView{p.camera().camera(), *m};
    }
  }
  if (!p.calibration().empty()) {
    projector.geometry_source = GeometrySource::calibration;
  } else if (!p.homography().empty()) {
    projector.geometry_source = GeometrySource::homography;
    if (direct) projector.homography = *direct;
  } else if (p.has_camera()) {
    projector.geometry_source = GeometrySource::camera;
  } else {
    projector.geometry_source = p.has_region() ? GeometrySource::region : GeometrySource::whole_screen;
    if (p.has_region()) {
      projector.region = part;
    } else if (screen != nullptr) {
      projector.region = screen->area();
    }
  }
}

Content content(Checker& check, const std::string& at, const schema::Content& c) {
  Content content;
  const std::optional<ContentRole> role = check.name(at + ".role", c.role(), kContentRoleNames);
  content.role = role.value_or(ContentRole::full);
  const bool lights = role == ContentRole::lights;
  if (lights && c.lights().empty()) {
    check.fail(at + ".lights",
               "role 'lights' needs its lights: indices and ranges of the scene's lights (\"0-6\", "
               "\"0, 3, 7-9\") or \"auto\"");
  }
  if (lights) {
    content.automatic = c.lights() == "auto";
    content.ambient = c.ambient();
    if (!c.lights().empty() && !content.automatic) {
      if (auto list = parse_light_list(c.lights()); !list) {
        check.fail(at + ".lights", list.error());
      } else {
        content.lights = std::move(list).value();
      }
    }
  }
  if (!lights && !c.lights().empty()) check.fail(at + ".lights", "only a projector of role 'lights' takes lights");
  if (!lights && c.ambient()) check.fail(at + ".ambient", "only a projector of role 'lights' takes ambient");
  check.non_negative(at + ".blur_radius", c.blur_radius());
  if (role != ContentRole::defocus && c.blur_radius() != 0.0) {
    check.fail(at + ".blur_radius", "only a projector of role 'defocus' has a blur radius");
  }
  if (role == ContentRole::defocus) {
    content.blur_radius = c.blur_radius() != 0.0 ? c.blur_radius() : defaults::kBlurRadius;
  }
  return content;
}

Projector parse_projector(const schema::Projector& p, const std::string& at, const std::vector<Screen>& screens,
                          const std::string& config_dir, std::set<std::string>& ids, Checker& check) {
  Projector projector;
  projector.id = p.id();
  check.id(at + ".id", p.id(), ids, "projector");
  projector.host = p.host().empty() ? "localhost" : p.host();
  if (p.width() == 0 || p.width() > kMaxPixels) {
    check.fail(at + ".width",
               "must be 1.." + std::to_string(kMaxPixels) + " pixels (got " + std::to_string(p.width()) + ")");
  }
  if (p.height() == 0 || p.height() > kMaxPixels) {
    check.fail(at + ".height",
               "must be 1.." + std::to_string(kMaxPixels) + " pixels (got " + std::to_string(p.height()) + ")");
  }
  projector.width = static_cast<int>(std::min(p.width(), kMaxPixels));
  projector.height = static_cast<int>(std::min(p.height(), kMaxPixels));
  projector.screen = screen_of(check, at + ".screen", p.screen(), screens);
  const Screen* screen = projector.screen < screens.size() ? &screens[projector.screen] : nullptr;
  geometry_source(check, at, p, screen, config_dir, projector);
  projector.output.kind = check.name(at + ".output.kind", p.output().kind(), kOutputKindNames).value_or(OutputKind{});
  projector.output.monitor = p.output().monitor();
  projector.output.fullscreen = p.output().fullscreen();
  projector.eye = check.name(at + ".eye", p.eye(), kEyeNames).value_or(Eye::mono);
  projector.rendering = check.name(at + ".rendering", p.rendering(), kRenderMethodNames).value_or(RenderMethod{});
  check.non_negative(at + ".blend_ramp", p.blend_ramp());
  projector.blend_ramp = p.blend_ramp();
  if (auto response = parse_response(p); !response) {
    // The model's messages start with the field ("response.table[3]: …").
    const std::string& e = response.error();
    const auto colon = e.find(": ");
    check.fail(at + "." + e.substr(0, colon), colon == std::string::npos ? e : e.substr(colon + 2));
  } else {
    projector.response = std::move(response).value();
  }
  projector.content = content(check, at + ".content", p.content());
  const std::size_t before = check.count();
  if (p.has_color_fields()) {
    projector.color_fields = parse_color_fields(p.color_fields(), at + ".color_fields", check.problems());
  }
  if (p.has_up_conversion()) {
    projector.up_conversion = parse_up_conversion(p.up_conversion(), at + ".up_conversion", check.problems());
  }
  if (check.count() == before) {  // each well formed: together?
    if (auto problem = up_conversion_with_fields(projector.up_conversion, projector.color_fields)) {
      check.fail(at + "." + problem->path, problem->message);
    }
  }
  return projector;
}

}  // namespace

std::vector<Projector> parse_projectors(const schema::Installation& installation, const std::vector<Screen>& screens,
                                        const std::string& config_dir, Checker& check) {
  if (installation.projectors().empty()) check.fail("projectors", "at least one projector is needed");
  std::vector<Projector> projectors;
  std::set<std::string> ids;
  for (int i = 0; i < installation.projectors_size(); ++i) {
    projectors.push_back(parse_projector(installation.projectors(i), "projectors[" + std::to_string(i) + "]", screens,
                                         config_dir, ids, check));
  }
  return projectors;
}

}  // namespace optique::config
