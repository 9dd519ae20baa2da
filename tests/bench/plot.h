#pragma once
// A small plot drawn by hand into an RGB image, for benchmark PNGs: panels with
// log or linear axes, grid lines, dots and lines; no text (the Markdown next to
// it says what the axes and colours are).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "image/image.h"

namespace optique::bench {

class Plot {
 public:
  Plot(int width, int height) : image_(width, height, 3) {
    std::fill(image_.pixels.begin(), image_.pixels.end(), std::uint8_t{255});
  }

  // A panel at (x0, y0) of size w × h over [x_lo, x_hi] × [y_lo, y_hi], each axis
  // logarithmic or linear.
  struct Panel {
    int x0, y0, w, h;
    double x_lo, x_hi, y_lo, y_hi;
    bool log_x = true;
    bool log_y = true;
    [[nodiscard]] glm::dvec2 at(double x, double y) const {
      const double u = log_x ? (std::log10(x) - std::log10(x_lo)) / (std::log10(x_hi) - std::log10(x_lo))
                             : (x - x_lo) / (x_hi - x_lo);
      const double v = log_y ? (std::log10(y) - std::log10(y_lo)) / (std::log10(y_hi) - std::log10(y_lo))
                             : (y - y_lo) / (y_hi - y_lo);
      return {x0 + u * w, y0 + h - v * h};
    }
  };

  // Axes, vertical grid lines at `x_ticks`, horizontal ones at every decade (log
  // y) or at `y_ticks` (linear y).
  void frame(const Panel& p, const std::vector<double>& x_ticks, const std::vector<double>& y_ticks = {}) {
    const glm::u8vec3 grid(220, 220, 220);
    if (p.log_y) {
      for (double d = std::pow(10.0, std::floor(std::log10(p.y_lo))); d <= p.y_hi; d *= 10.0) {
        if (d >= p.y_lo) line(p.at(p.x_lo, d), p.at(p.x_hi, d), grid, 1);
      }
    }
    for (const double y : y_ticks) line(p.at(p.x_lo, y), p.at(p.x_hi, y), grid, 1);
    for (const double x : x_ticks) line(p.at(x, p.y_lo), p.at(x, p.y_hi), grid, 1);
    const glm::u8vec3 black(0, 0, 0);
    line({p.x0, p.y0}, {p.x0, p.y0 + p.h}, black, 1);
    line({p.x0, p.y0 + p.h}, {p.x0 + p.w, p.y0 + p.h}, black, 1);
  }

  // One series of a line chart: a dot at each point (pixels), joined in order.
  void curve(const std::vector<glm::dvec2>& points, glm::u8vec3 colour) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      dot(points[i], colour, 4);
      if (i > 0) line(points[i - 1], points[i], colour, 1);
    }
  }

  void line(glm::dvec2 a, glm::dvec2 b, glm::u8vec3 colour, int thickness) {
    const int steps = static_cast<int>(std::ceil(std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)))) + 1;
    for (int i = 0; i <= steps; ++i) dot(a + (b - a) * (static_cast<double>(i) / steps), colour, thickness);
  }

  void dot(glm::dvec2 c, glm::u8vec3 colour, int radius) {
    for (int dy = -radius; dy <= radius; ++dy) {
      for (int dx = -radius; dx <= radius; ++dx) {
        const int x = static_cast<int>(std::lround(c.x)) + dx;
        const int y = static_cast<int>(std::lround(c.y)) + dy;
        if (x < 0 || y < 0 || x >= image_.width || y >= image_.height) continue;
        for (int k = 0; k < 3; ++k) image_.at(x, y, k) = colour[k];
      }
    }
  }

  [[nodiscard]] const image::ByteImage& image() const { return image_; }

 private:
  image::ByteImage image_;
};

}  // namespace optique::bench
