#pragma once
// What a projector does with the signal it is sent: its response (how signal
// becomes light), the depth the signal is quantized to, the black it shows at
// signal 0 and its brightness. A node sends response⁻¹ of the light it rendered
// so that the projector adds exactly that light on top of its own black:
//
//   emitted(v) = brightness · (black_level + (1 − black_level) · response(v))
//   signal_for(L) = quantize(response⁻¹(L / (brightness · (1 − black_level))))
//
// so emitted(signal_for(L)) = black + L up to quantization, and the light of a
// stacked group adds linearly: Σ emitted = Σ black + Σ rendered. The renderer's
// output pass does the same in GLSL (render/scene_renderer.cpp); the screen
// simulator decodes captured signals with emitted().

#include <string>
#include <vector>

#include "config/response.h"
#include "image/image.h"
#include "util/result.h"

namespace optique::optics {

class ProjectorModel {
 public:
  using Curve = config::ResponseCurve;

  // The sRGB curve, 8 bits, no black, brightness 1: what a projector without
  // response settings is taken to be.
  ProjectorModel() = default;
  // A projector's response as its config states it (checked when parsed).
  explicit ProjectorModel(const config::ProjectorResponse& response);

  // Normalized response: light in [0, 1] for a signal in [0, 1], non-decreasing.
  [[nodiscard]] double response(double signal) const;
  // The smallest signal whose response reaches `light` (clamped to [0, 1]).
  [[nodiscard]] double inverse_response(double light) const;
  // To the nearest of the 2^bits levels.
  [[nodiscard]] double quantize(double signal) const;
  // Light leaving the lens for a signal, in the installation's unit of light.
  [[nodiscard]] double emitted(double signal) const;
  // The quantized signal that makes the projector add `light` to its black;
  // light beyond what it can add is clipped.
  [[nodiscard]] double signal_for(double light) const;

  // Light at signal 0 (brightness · black level) and at full signal.
  [[nodiscard]] double black() const { return response_.brightness * response_.black_level; }
  [[nodiscard]] double white() const { return response_.brightness; }
  // The most light it can add above its black.
  [[nodiscard]] double headroom() const { return response_.brightness * (1.0 - response_.black_level); }

  [[nodiscard]] int levels() const { return (1 << response_.bits) - 1; }  // the largest code
  // The response as the config states it (curve, gamma, table, bits, black
  // level, brightness), for the output pass that does the same in GLSL.
  [[nodiscard]] const config::ProjectorResponse& settings() const { return response_; }

 private:
  config::ProjectorResponse response_;  // its defaults: sRGB, 8 bits, no black, brightness 1
};

// The light a projector emits for a captured signal image (values in [0, 1] as
// read from its 8- or 16-bit PNG; snapped to the projector's levels): RGB
// through the model, alpha 1.
[[nodiscard]] image::FloatImage emitted_image(const image::FloatImage& signal, const ProjectorModel& model);

}  // namespace optique::optics
