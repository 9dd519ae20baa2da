#pragma once
// What a viewer sees on a screen with one eye: a screen image. Projectors that
// light the same screen for the same eye make one (config::same_screen_image);
// compose writes one composite per screen image and render-reference one reference,
// in folders of the same name, so each composite has its reference.

#include <string>
#include <vector>

#include "config/installation.h"

namespace optique::tools {

struct ScreenImage {
  const config::Screen* screen = nullptr;
  config::Eye eye = config::Eye::mono;
  std::vector<const config::Projector*> projectors;  // none: a screen no projector lights (mono)
};

// Every screen image, in the order their first projector appears; then, mono,
// the screens no projector lights.
[[nodiscard]] std::vector<ScreenImage> screen_images(const config::Installation& installation);

// The folder name of a screen image: the screen id, with ".left" or ".right" for
// a stereo eye.
[[nodiscard]] std::string screen_image_folder(const std::string& screen_id, config::Eye eye);

}  // namespace optique::tools
