#include "optics/projector_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace optique::optics {
namespace {

double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double l) { return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055; }

}  // namespace

ProjectorModel::ProjectorModel(const config::ProjectorResponse& response)
    : curve_(response.curve),
      gamma_(response.gamma),
      table_(response.table),
      bits_(response.bits),
      black_level_(response.black_level),
      brightness_(response.brightness) {}

double ProjectorModel::response(double signal) const {
  const double v = std::clamp(signal, 0.0, 1.0);
  switch (curve_) {
    case Curve::srgb:
      return srgb_to_linear(v);
    case Curve::gamma:
      return std::pow(v, gamma_);
    case Curve::table: {
      const double at = v * static_cast<double>(table_.size() - 1);
      const auto i = std::min(static_cast<std::size_t>(at), table_.size() - 2);
      const double f = at - static_cast<double>(i);
      return table_[i] + f * (table_[i + 1] - table_[i]);
    }
  }
  return v;
}

double ProjectorModel::inverse_response(double light) const {
  const double l = std::clamp(light, 0.0, 1.0);
  switch (curve_) {
    case Curve::srgb:
      return std::clamp(linear_to_srgb(l), 0.0, 1.0);
    case Curve::gamma:
      return std::pow(l, 1.0 / gamma_);
    case Curve::table: {
      // The first segment that reaches l; a flat segment maps to its start, so
      // the smallest signal giving that light is sent.
      const auto upper = std::lower_bound(table_.begin(), table_.end(), l);
      if (upper == table_.begin()) return 0.0;
      const auto i = static_cast<std::size_t>(upper - table_.begin()) - 1;
      const double a = table_[i];
      const double b = table_[i + 1];
      const double f = b > a ? (l - a) / (b - a) : 0.0;
      return (static_cast<double>(i) + f) / static_cast<double>(table_.size() - 1);
    }
  }
  return l;
}

double ProjectorModel::quantize(double signal) const {
  const double n = levels();
  return std::round(std::clamp(signal, 0.0, 1.0) * n) / n;
}

double ProjectorModel::emitted(double signal) const {
  return brightness_ * (black_level_ + (1.0 - black_level_) * response(signal));
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
