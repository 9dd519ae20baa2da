#include "config/response.h"

#include <cmath>
#include <string>

#include "util/number_text.h"

namespace optique::config {

using util::number_text;

Result<ProjectorResponse> parse_response(const schema::Projector& projector) {
  ProjectorResponse model;
  const schema::Response& r = projector.response();
  if (r.gamma() != 0.0 && !r.table().empty()) {
    return Error{"response: give either gamma or table, not both"};
  }
  if (r.gamma() != 0.0) {
    if (!std::isfinite(r.gamma()) || r.gamma() <= 0.0 || r.gamma() > 10.0) {
      return Error{"response.gamma: must be in (0, 10] (got " + number_text(r.gamma()) + ")"};
    }
    model.curve = ResponseCurve::gamma;
    model.gamma = r.gamma();
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
    model.curve = ResponseCurve::table;
    model.table.assign(r.table().begin(), r.table().end());
  }
  if (r.bits() != 0) {
    if (r.bits() > 16) return Error{"response.bits: must be 1…16 (got " + std::to_string(r.bits()) + ")"};
    model.bits = static_cast<int>(r.bits());
  }
  const double black = projector.black_level();
  if (!std::isfinite(black) || black < 0.0 || black >= 1.0) {
    return Error{"black_level: must be in [0, 1), a fraction of full white (got " + number_text(black) + ")"};
  }
  model.black_level = black;
  const double brightness = projector.brightness();
  if (!std::isfinite(brightness) || brightness < 0.0) {
    return Error{"brightness: must be > 0, relative to the installation's unit of light (got " +
                 number_text(brightness) + ")"};
  }
  if (brightness > 0.0) model.brightness = brightness;
  return model;
}

}  // namespace optique::config
