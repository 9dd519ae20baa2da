#pragma once
// A projector's response as the installation states it, checked and typed: how
// the signal it is sent becomes light (optics/projector_model.h evaluates it).

#include <vector>

#include "optique/config.pb.h"
#include "util/result.h"

namespace optique::config {

enum class ResponseCurve { srgb, gamma, table };

struct ProjectorResponse {
  ResponseCurve curve = ResponseCurve::srgb;
  double gamma = 2.2;         // curve gamma: light = signal^gamma
  std::vector<double> table;  // curve table: light at evenly spaced signals, 0 … 1, non-decreasing
  int bits = 8;               // signal depth, 1 … 16
  double black_level = 0.0;   // light at signal 0, a fraction of full white, [0, 1)
  double brightness = 1.0;    // full white in the installation's unit of light, > 0
};

// Fails, naming the field, on a gamma outside (0, 10], a table that is too short,
// not finite, not from 0 to 1 or decreasing, bits outside 1…16, a black level
// outside [0, 1) or a brightness < 0. Paths are relative to the projector
// ("response.table[3]: …").
[[nodiscard]] Result<ProjectorResponse> parse_response(const schema::Projector& projector);

}  // namespace optique::config
