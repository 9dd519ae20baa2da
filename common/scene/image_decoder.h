#pragma once
// How a scene's images become textures. The scene library reads no image format
// itself: whoever draws the scene passes a decoder (image::decode_texture, with
// OpenImageIO); the master, which animates the scene but never draws it, passes
// none, and so links no image library.

#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "scene/definition.h"
#include "util/result.h"

namespace optique::scene {

// Encoded bytes (PNG, JPEG, …) and their MIME type, as the file records it
// (possibly empty) → 8-bit RGBA, sRGB-encoded as stored, alpha unassociated.
using ImageDecoder = std::function<Result<Texture>(std::span<const std::uint8_t> bytes, const std::string& mime_type)>;

}  // namespace optique::scene
