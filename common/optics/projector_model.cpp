#include "optics/projector_model.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "util/number_text.h"

namespace optique::optics {
namespace {

using util::number_text;

double srgb_to_linear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }
double linear_to_srgb(double l) { return l <= 0.0031308 ? l * 12.92 : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055; }

}  // namespace

Result<ProjectorModel> ProjectorModel::from_config(const config::Projector& projector) {
  ProjectorModel model;
  const config::Response& r = projector.response();
  if (r.gamma() != 0.0 && !r.table().empty()) {
    return Error{"response: give either gamma or table, not both"};
  }
  if (r.gamma() != 0.0) {
    if (!std::isfinite(r.gamma()) || r.gamma() <= 0.0 || r.gamma() > 10.0) {
      return Error{"response.gamma: must be in (0, 10] (got " + number_text(r.gamma()) + ")"};
    }
    model.curve_ = Curve::gamma;
    model.gamma_ = r.gamma();
  } else if (!r.table().empty()) {
    if (r.table_size() < 2) {
      return Error{"response.table: needs at least 2 values (light at signal 0 and at signal 1), got " +
                   std::to_string(r.table_size())};
    }
    if (r.table_size() > 65536) {
      return Error{"response.table: at most 65536 values (got " + std::to_string(r.table_size()) + ")"};
    }
    for (int i = 0; i < r.table_size(); ++i) {
      const std::string path = "response.table[" + std::to_string(i) + "]";
      const double v = r.table(i);
      if (!std::isfinite(v)) return Error{path + ": must be a finite number (got " + number_text(v) + ")"};
      if (i > 0 && v < r.table(i - 1)) {
        return Error{path + ": the response must not decrease (" + number_text(v) + " after " +
                     number_text(r.table(i - 1)) + "); a measured table that dips needs smoothing first"};
      }
    }
    if (r.table(0) != 0.0 || r.table(r.table_size() - 1) != 1.0) {
      return Error{"response.table: must go from 0 (signal 0) to 1 (full signal), got " + number_text(r.table(0)) +
                   " … " + number_text(r.table(r.table_size() - 1)) +
                   "; normalize the measured light, and give the light at signal 0 as black_level"};
    }
    model.curve_ = Curve::table;
    model.table_.assign(r.table().begin(), r.table().end());
  }
  if (r.bits() != 0) {
    if (r.bits() > 16) return Error{"response.bits: must be 1…16 (got " + std::to_string(r.bits()) + ")"};
    model.bits_ = static_cast<int>(r.bits());
  }
  const double black = projector.black_level();
  if (!std::isfinite(black) || black < 0.0 || black >= 1.0) {
    return Error{"black_level: must be in [0, 1), a fraction of full white (got " + number_text(black) + ")"};
  }
  model.black_level_ = black;
  const double brightness = projector.brightness();
  if (!std::isfinite(brightness) || brightness < 0.0) {
    return Error{"brightness: must be > 0, relative to the installation's unit of light (got " +
                 number_text(brightness) + ")"};
  }
  if (brightness > 0.0) model.brightness_ = brightness;
  return model;
}

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
