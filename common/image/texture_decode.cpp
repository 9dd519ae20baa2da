#include "image/texture_decode.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <vector>

#include "util/message_text.h"

namespace optique::image {
namespace {

using util::one_line;

// A file name extension for OpenImageIO to pick its reader by: from the MIME type
// tinygltf records (or the data URI's), else ".png" (OpenImageIO then still
// checks the bytes' signature).
std::string extension_for(const std::string& mime_type) {
  if (mime_type == "image/jpeg") return ".jpg";
  if (mime_type == "image/bmp") return ".bmp";
  if (mime_type == "image/gif") return ".gif";
  if (mime_type == "image/webp") return ".webp";
  return ".png";
}

}  // namespace

Result<scene::Texture> decode_texture(std::span<const std::uint8_t> bytes, const std::string& mime_type) {
  if (bytes.empty()) return Error{"no image data"};
  OIIO::Filesystem::IOMemReader memory(bytes.data(), bytes.size());
  OIIO::Filesystem::IOProxy* proxy = &memory;
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // PNG: no premultiplication on read
  // OpenImageIO 2.4 ignores open()'s ioproxy argument when a config is given; the
  // config attribute works.
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  auto input = OIIO::ImageInput::open("image" + extension_for(mime_type), &config);
  if (!input) return Error{one_line(OIIO::geterror())};
  const OIIO::ImageSpec& spec = input->spec();
  constexpr int kMaxSide = 16384;
  if (spec.width <= 0 || spec.height <= 0 || spec.width > kMaxSide || spec.height > kMaxSide || spec.depth > 1 ||
      spec.nchannels <= 0) {
    return Error{"unsupported image size " + std::to_string(spec.width) + "x" + std::to_string(spec.height)};
  }
  const int channels = std::min(spec.nchannels, 4);
  const auto pixels = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(spec.height);
  std::vector<std::uint8_t> stored(pixels * static_cast<std::size_t>(channels));
  if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, stored.data())) {
    return Error{one_line(input->geterror())};
  }
  scene::Texture out;
  out.width = spec.width;
  out.height = spec.height;
  out.rgba.resize(pixels * 4);
  // Grey, grey + alpha, RGB or RGBA (first four channels).
  const bool grey = channels <= 2;
  const bool alpha = channels == 2 || channels == 4;
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint8_t* in = stored.data() + i * static_cast<std::size_t>(channels);
    std::uint8_t* to = out.rgba.data() + i * 4;
    to[0] = in[0];
    to[1] = grey ? in[0] : in[1];
    to[2] = grey ? in[0] : in[2];
    to[3] = alpha ? in[channels - 1] : std::uint8_t{255};
  }
  return out;
}

}  // namespace optique::image
