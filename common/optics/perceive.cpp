#include "optics/perceive.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

namespace optique::optics {
namespace {

// Bilinear, pixel centres at half-integers, zero outside.
void add_sample(const image::FloatImage& light, double x, double y, float weight, const bool (&on)[3], float* out) {
  const double fx = x - 0.5;
  const double fy = y - 0.5;
  const int x0 = static_cast<int>(std::floor(fx));
  const int y0 = static_cast<int>(std::floor(fy));
  const auto tx = static_cast<float>(fx - x0);
  const auto ty = static_cast<float>(fy - y0);
  const float wx[2] = {1.0f - tx, tx};
  const float wy[2] = {1.0f - ty, ty};
  for (int j = 0; j < 2; ++j) {
    const int yy = y0 + j;
    if (yy < 0 || yy >= light.height) continue;
    for (int i = 0; i < 2; ++i) {
      const int xx = x0 + i;
      if (xx < 0 || xx >= light.width) continue;
      const float w = weight * wx[i] * wy[j];
      for (int c = 0; c < 3; ++c) {
        if (on[c]) out[c] += w * light.at(xx, yy, c);
      }
    }
  }
}

}  // namespace

image::FloatImage perceive(std::span<const Emission> emissions, int width, int height, const Exposure& exposure) {
  assert(exposure.duration > 0.0);
  image::FloatImage out(width, height, 4);
  for (int i = 3; i < static_cast<int>(out.pixels.size()); i += 4) out.pixels[static_cast<std::size_t>(i)] = 1.0f;
  const double open = exposure.centre - 0.5 * exposure.duration;
  const double close = exposure.centre + 0.5 * exposure.duration;
  for (const Emission& e : emissions) {
    assert(e.light != nullptr && e.light->channels >= 3 && e.on_fraction > 0.0);
    const double a = std::max(e.start, open);
    const double b = std::min(e.end, close);
    if (b <= a) continue;
    // Where the retina is on the screen, relative to the exposure's centre, as
    // the window opens and closes: light at screen point s lands on retina point
    // s − v·(t − centre), so retina point r sees s = r + v·(t − centre).
    const glm::dvec2 from = exposure.velocity * (a - exposure.centre);
    const glm::dvec2 to = exposure.velocity * (b - exposure.centre);
    const double travel = glm::length(to - from);
    const int samples = std::max(1, static_cast<int>(std::ceil(2.0 * travel)));
    const auto weight = static_cast<float>((b - a) / (exposure.duration * e.on_fraction * samples));
    const bool on[3] = {e.red, e.green, e.blue};
    for (int k = 0; k < samples; ++k) {
      const glm::dvec2 shift = from + (to - from) * ((k + 0.5) / samples);
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          add_sample(*e.light, x + 0.5 + shift.x, y + 0.5 + shift.y, weight, on, &out.at(x, y, 0));
        }
      }
    }
  }
  return out;
}

double fringe_width(const image::FloatImage& image, int x0, int y0, int x1, int y1, bool along_x) {
  x0 = std::clamp(x0, 0, image.width);
  x1 = std::clamp(x1, 0, image.width);
  y0 = std::clamp(y0, 0, image.height);
  y1 = std::clamp(y1, 0, image.height);
  // Each channel's edges cross half of that channel's brightest value in the box.
  float peak[3] = {0.0f, 0.0f, 0.0f};
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      for (int c = 0; c < 3; ++c) peak[c] = std::max(peak[c], image.at(x, y, c));
    }
  }
  if (std::min({peak[0], peak[1], peak[2]}) <= 0.0f) return 0.0;
  const int lines_from = along_x ? y0 : x0;
  const int lines_to = along_x ? y1 : x1;
  const int steps_from = along_x ? x0 : y0;
  const int steps_to = along_x ? x1 : y1;
  double spread = 0.0;
  long edges = 0;
  std::vector<double> crossings[3];
  for (int line = lines_from; line < lines_to; ++line) {
    for (int c = 0; c < 3; ++c) {
      crossings[c].clear();
      const float half = 0.5f * peak[c];
      for (int k = steps_from; k + 1 < steps_to; ++k) {
        const float a = along_x ? image.at(k, line, c) : image.at(line, k, c);
        const float b = along_x ? image.at(k + 1, line, c) : image.at(line, k + 1, c);
        if ((a < half) == (b < half)) continue;
        // Between the two pixel centres, where the line through them meets half.
        crossings[c].push_back(k + 0.5 + (half - a) / (b - a));
      }
    }
    // Edges every channel has: the i-th crossing of each is the same edge.
    if (crossings[0].size() != crossings[1].size() || crossings[0].size() != crossings[2].size()) continue;
    for (std::size_t i = 0; i < crossings[0].size(); ++i) {
      const double lo = std::min({crossings[0][i], crossings[1][i], crossings[2][i]});
      const double hi = std::max({crossings[0][i], crossings[1][i], crossings[2][i]});
      spread += hi - lo;
      ++edges;
    }
  }
  return edges == 0 ? 0.0 : spread / static_cast<double>(edges);
}

}  // namespace optique::optics
