// Where each projector's pixels land on its screen, once every section is
// known to be right: an aligned projector's from its rectangle, a calibrated
// one's from its file, a camera view's from a partner seen by the same camera.
#include <filesystem>

#include <glm/matrix.hpp>

#include "config/calibration_file.h"
#include "config/sections.h"

namespace optique::config {

void resolve_homographies(const schema::Installation& installation, Installation& built, const std::string& config_dir,
                          std::vector<Problem>& problems) {
  // Calibration files, direct matrices and rectangles first: camera views
  // relate a projector to a partner that has its own.
  std::vector<bool> known(built.projectors.size(), false);
  for (std::size_t i = 0; i < built.projectors.size(); ++i) {
    Projector& projector = built.projectors[i];
    switch (projector.geometry_source) {
      case GeometrySource::calibration: {
        const schema::Projector& p = installation.projectors(static_cast<int>(i));
        auto h = read_calibration_homography((std::filesystem::path(config_dir) / p.calibration()).string(), p.width(),
                                             p.height());
        if (!h) {
          problems.push_back({projector_path(i) + ".calibration", h.error()});
          continue;
        }
        projector.homography = h.value();
        break;
      }
      case GeometrySource::homography:
        break;  // as the config gives it
      case GeometrySource::camera:
        continue;  // below, from a partner
      case GeometrySource::region:
      case GeometrySource::whole_screen:
        projector.homography = geometry::aligned_homography(*projector.region, projector.width, projector.height);
        break;
    }
    known[i] = true;
  }
  for (std::size_t i = 0; i < built.projectors.size(); ++i) {
    Projector& p = built.projectors[i];
    if (p.geometry_source != GeometrySource::camera) continue;
    const auto partner = std::find_if(built.projectors.begin(), built.projectors.end(), [&](const Projector& q) {
      return known[static_cast<std::size_t>(&q - built.projectors.data())] && q.camera &&
             q.camera->camera == p.camera->camera && q.screen == p.screen;
    });
    if (partner == built.projectors.end()) {
      problems.push_back({projector_path(i) + ".camera",
                          "no projector on screen '" + built.screen_of(p).id + "' seen by camera '" + p.camera->camera +
                              "' has a homography or calibration to relate this one to"});
      continue;
    }
    // Partner pixels → camera → this projector's pixels.
    p.homography =
        glm::inverse(p.camera->projector_to_camera) * partner->camera->projector_to_camera * partner->homography;
    known[i] = true;
  }
  for (std::size_t i = 0; i < built.projectors.size(); ++i) {
    if (!known[i]) continue;
    const Projector& p = built.projectors[i];
    auto geometry = geometry::ProjectorGeometry::make(p.homography, p.width, p.height);
    if (!geometry) {
      problems.push_back({projector_path(i) + ".homography", geometry.error()});
      continue;
    }
    if (auto oblique = geometry::oblique_projection(geometry.value(), built.screen_of(p).area()); !oblique) {
      problems.push_back({projector_path(i), oblique.error() + " (screen '" + built.screen_of(p).id + "')"});
    }
  }
}

}  // namespace optique::config
