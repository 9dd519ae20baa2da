#include "config/geometry.h"

#include <filesystem>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "config/calibration_file.h"

namespace optique::config {
namespace {

glm::dmat3 matrix_of(const google::protobuf::RepeatedField<double>& nine) {
  return geometry::homography_from_rows(std::span<const double, 9>(nine.data(), 9));
}

void store(Projector& projector, const glm::dmat3& homography) {
  projector.clear_homography();
  for (double v : geometry::homography_rows(homography)) projector.add_homography(v);
}

const Screen* screen_of(const Installation& installation, const Projector& projector) {
  for (const Screen& s : installation.screens()) {
    if (s.id() == projector.screen()) return &s;
  }
  return nullptr;
}

}  // namespace

geometry::WorldRect screen_region(const Screen& screen, const Region& region) {
  geometry::WorldRect rect;
  const glm::dvec3 origin(screen.origin(0), screen.origin(1), screen.origin(2));
  rect.right = glm::normalize(glm::dvec3(screen.right(0), screen.right(1), screen.right(2)));
  rect.up = glm::normalize(glm::dvec3(screen.up(0), screen.up(1), screen.up(2)));
  rect.lower_left = origin + rect.right * region.x() + rect.up * region.y();
  rect.width = region.width();
  rect.height = region.height();
  return rect;
}

geometry::WorldRect whole_screen(const Screen& screen) {
  Region region;
  region.set_width(screen.width());
  region.set_height(screen.height());
  return screen_region(screen, region);
}

bool same_screen_image(const Projector& a, const Projector& b) {
  return a.screen() == b.screen() && a.eye() == b.eye();
}

bool same_layer(const Projector& a, const Projector& b) {
  const Content& x = a.content();
  const Content& y = b.content();
  const auto role = [](const Content& c) { return c.role().empty() ? std::string("full") : c.role(); };
  return role(x) == role(y) && x.lights() == y.lights() && x.ambient() == y.ambient() && x.lights() != "auto";
}

bool same_blend_group(const Projector& a, const Projector& b) {
  return same_screen_image(a, b) && (a.id() == b.id() || same_layer(a, b));
}

geometry::ScreenRect usable_area(const Screen& screen) {
  return geometry::ScreenRect{glm::dvec2(0.0), glm::dvec2(screen.width(), screen.height())};
}

Result<geometry::ProjectorGeometry> projector_geometry(const Projector& projector) {
  const int width = static_cast<int>(projector.width());
  const int height = static_cast<int>(projector.height());
  if (projector.homography_size() == 9) {
    return geometry::ProjectorGeometry::make(matrix_of(projector.homography()), width, height);
  }
  if (!projector.has_region())
    return Error{"projector '" + projector.id() + "' has no geometry (load the config first)"};
  const Region& r = projector.region();
  const geometry::ScreenRect rect{glm::dvec2(r.x(), r.y()), glm::dvec2(r.x() + r.width(), r.y() + r.height())};
  return geometry::ProjectorGeometry::make(geometry::aligned_homography(rect, width, height), width, height);
}

std::vector<Problem> resolve_geometry(Installation& installation, const std::string& config_dir) {
  std::vector<Problem> problems;
  auto at = [](int i) { return "projectors[" + std::to_string(i) + "]"; };
  // Direct geometry first; camera-only projectors then take theirs from a partner.
  for (int i = 0; i < installation.projectors_size(); ++i) {
    Projector& p = *installation.mutable_projectors(i);
    if (!p.calibration().empty()) {
      auto h = config::read_calibration_homography((std::filesystem::path(config_dir) / p.calibration()).string());
      if (!h) {
        problems.push_back({at(i) + ".calibration", h.error()});
        continue;
      }
      store(p, h.value());
      p.clear_calibration();  // the installation now carries it, for nodes and for writing it back
    }
  }
  for (int i = 0; i < installation.projectors_size(); ++i) {
    // Validation allows a camera view without a region only; defaults gave every
    // projector with nothing at all a region.
    if (!installation.projectors(i).homography().empty() || !installation.projectors(i).has_camera()) continue;
    Projector& p = *installation.mutable_projectors(i);
    const Projector* partner = nullptr;
    for (int j = 0; j < installation.projectors_size(); ++j) {
      const Projector& q = installation.projectors(j);
      if (!q.homography().empty() && q.has_camera() && q.camera().camera() == p.camera().camera() &&
          q.screen() == p.screen()) {
        partner = &q;
        break;
      }
    }
    if (partner == nullptr) {
      problems.push_back({at(i) + ".camera", "no projector on screen '" + p.screen() + "' seen by camera '" +
                                                 p.camera().camera() +
                                                 "' has a homography or calibration to relate this one to"});
      continue;
    }
    // Partner pixels → camera → this projector's pixels.
    const glm::dmat3 partner_to_this =
        glm::inverse(matrix_of(p.camera().homography())) * matrix_of(partner->camera().homography());
    store(p, partner_to_this * matrix_of(partner->homography()));
  }
  for (int i = 0; i < installation.projectors_size(); ++i) {
    const Projector& p = installation.projectors(i);
    const Screen* screen = screen_of(installation, p);
    if (screen == nullptr) continue;
    auto geometry = projector_geometry(p);
    if (!geometry) {
      problems.push_back({at(i) + ".homography", geometry.error()});
      continue;
    }
    if (auto oblique = geometry::oblique_projection(geometry.value(), usable_area(*screen)); !oblique) {
      problems.push_back({at(i), oblique.error() + " (screen '" + screen->id() + "')"});
    }
  }
  return problems;
}

}  // namespace optique::config
