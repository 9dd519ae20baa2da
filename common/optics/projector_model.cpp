#include "optics/projector_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace optique::optics {
namespace {

double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double l) { return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055; }

}  // namespace

ProjectorModel::ProjectorModel(const config::ProjectorResponse& response) : response_(response) {}

double ProjectorModel::response(double signal) const {
  const double v = std::clamp(signal, 0.0, 1.0);
  switch (response_.curve) {
    case Curve::srgb:
      return srgb_to_linear(v);
    case Curve::gamma:
      return std::pow(v, response_.gamma);
    case Curve::table: {
      const double at = v * static_cast<double>(response_.table.size() - 1);
      const auto i = std::min(static_cast<std::size_t>(at), response_.table.size() - 2);
      const double f = at - static_cast<double>(i);
      return response_.table[i] + f * (response_.table[i + 1] - response_.table[i]);
    }
  }
  return v;
}

double ProjectorModel::inverse_response(double light) const {
  const double l = std::clamp(light, 0.0, 1.0);
  switch (response_.curve) {
    case Curve::srgb:
      return std::clamp(linear_to_srgb(l), 0.0, 1.0);
    case Curve::gamma:
      return std::pow(l, 1.0 / response_.gamma);
    case Curve::table: {
      // The first segment that reaches l; a flat segment maps to its start, so
      // the smallest signal giving that light is sent.
      const auto upper = std::lower_bound(response_.table.begin(), response_.table.end(), l);
      if (upper == response_.table.begin()) return 0.0;
      const auto i = static_cast<std::size_t>(upper - response_.table.begin()) - 1;
      const double a = response_.table[i];
      const double b = response_.table[i + 1];
      const double f = b > a ? (l - a) / (b - a) : 0.0;
      return (static_cast<double>(i) + f) / static_cast<double>(response_.table.size() - 1);
    }
  }
  return l;
}

double ProjectorModel::quantize(double signal) const {
  const double n = levels();
  return std::round(std::clamp(signal, 0.0, 1.0) * n) / n;
}

double ProjectorModel::emitted(double signal) const {
  return response_.brightness * (response_.black_level + (1.0 - response_.black_level) * response(signal));
}

double ProjectorModel::signal_for(double light) const {
  assert(headroom() > 0.0);
  return quantize(inverse_response(light / headroom()));
}

image::FloatImage emitted_image(const image::FloatImage& signal, const ProjectorModel& model) {
  image::FloatImage light(signal.width, signal.height, 4);
  const int colours = std::min(signal.channels, 3);
  for (int y = 0; y < signal.height; ++y) {
    for (int x = 0; x < signal.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        // A grey signal (one channel) drives all three colours.
        const float v = signal.at(x, y, std::min(c, colours - 1));
        light.at(x, y, c) = static_cast<float>(model.emitted(model.quantize(v)));
      }
      light.at(x, y, 3) = 1.0f;
    }
  }
  return light;
}

}  // namespace optique::optics
