#pragma once
// Numbers as the benches' tables print them.

#include <cmath>
#include <cstdio>
#include <string>

namespace optique::bench {

// `value` with `decimals` digits after the point ("inf", "nan" as printf says).
[[nodiscard]] inline std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

// The same, or `not_finite` for an infinity or NaN (a PSNR of equal images).
[[nodiscard]] inline std::string fixed(double value, int decimals, const char* not_finite) {
  return std::isfinite(value) ? fixed(value, decimals) : not_finite;
}

}  // namespace optique::bench
