#include "image/image_io.h"

#include <OpenImageIO/imageio.h>

namespace optique::image {
namespace {

template <class T>
Result<void> write(const std::string& path, const Image<T>& image, OIIO::TypeDesc stored, OIIO::TypeDesc given) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) return Error{"cannot write " + path + ": " + OIIO::geterror()};
  OIIO::ImageSpec spec(image.width, image.height, image.channels, stored);
  if (!out->open(path, spec)) return Error{"cannot write " + path + ": " + out->geterror()};
  const bool ok = out->write_image(given, image.pixels.data());
  const std::string error = ok ? std::string() : out->geterror();
  if (!out->close() || !ok) return Error{"cannot write " + path + ": " + error};
  return {};
}

}  // namespace

Result<void> write_exr(const std::string& path, const FloatImage& image) {
  return write(path, image, OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT);
}

Result<void> write_png(const std::string& path, const ByteImage& image) {
  return write(path, image, OIIO::TypeDesc::UINT8, OIIO::TypeDesc::UINT8);
}

Result<void> write_png(const std::string& path, const WordImage& image) {
  return write(path, image, OIIO::TypeDesc::UINT16, OIIO::TypeDesc::UINT16);
}

Result<FloatImage> read_image(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return Error{"cannot read " + path + ": " + OIIO::geterror()};
  const OIIO::ImageSpec& spec = in->spec();
  FloatImage image(spec.width, spec.height, spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data())) {
    return Error{"cannot read " + path + ": " + in->geterror()};
  }
  return image;
}

}  // namespace optique::image
