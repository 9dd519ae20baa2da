#pragma once
// A scene's images (PNG, JPEG, … as OpenImageIO reads them) decoded from memory
// to 8-bit RGBA: grey becomes RGB, a missing alpha 255. Colour values are kept as
// stored (sRGB-encoded), alpha unassociated. Pass it as the scene::ImageDecoder
// wherever a scene is drawn.

#include <cstdint>
#include <span>
#include <string>

#include "scene/definition.h"
#include "util/result.h"

namespace optique::image {

[[nodiscard]] Result<scene::Texture> decode_texture(std::span<const std::uint8_t> bytes, const std::string& mime_type);

}  // namespace optique::image
