#include "tools/screen_images.h"

#include <algorithm>

#include "config/projector_groups.h"

namespace optique::tools {

std::vector<ScreenImage> screen_images(const config::Installation& installation) {
  std::vector<ScreenImage> images;
  for (const config::Projector& p : installation.projectors) {
    auto image = std::find_if(images.begin(), images.end(), [&](const ScreenImage& i) {
      return config::same_screen_image(*i.projectors.front(), p);
    });
    if (image != images.end()) {
      image->projectors.push_back(&p);
    } else {
      images.push_back({&installation.screen_of(p), p.eye, {&p}});
    }
  }
  const std::size_t lit = images.size();
  for (const config::Screen& screen : installation.screens) {
    const bool any = std::any_of(images.begin(), images.begin() + static_cast<std::ptrdiff_t>(lit),
                                 [&](const ScreenImage& i) { return i.screen == &screen; });
    if (!any) images.push_back({&screen, config::Eye::mono, {}});
  }
  return images;
}

std::string screen_image_folder(const std::string& screen_id, config::Eye eye) {
  return eye == config::Eye::mono ? screen_id : screen_id + "." + std::string(config::to_string(eye));
}

}  // namespace optique::tools
