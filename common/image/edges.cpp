#include "image/edges.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "image/compare.h"
#include "metrics/distribution.h"

namespace optique::image {
namespace {

// Luma along one line of the image: a row (horizontal) or a column.
std::vector<double> line(const FloatImage& image, int index, bool horizontal) {
  const int n = horizontal ? image.width : image.height;
  std::vector<double> values(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    values[static_cast<std::size_t>(i)] = horizontal ? luma(image, i, index) : luma(image, index, i);
  return values;
}

std::vector<double> gradient(const std::vector<double>& v) {
  std::vector<double> g(v.size(), 0.0);
  for (std::size_t i = 1; i + 1 < v.size(); ++i) g[i] = 0.5 * (v[i + 1] - v[i - 1]);
  return g;
}

// Centroid and spread (standard deviation) of |g| over [centre − h, centre + h]:
// where the edge is, and how wide.
struct EdgeProfile {
  double position = 0.0;
  double width = 0.0;
};

EdgeProfile profile(const std::vector<double>& g, int centre, int h) {
  double sum = 0.0;
  double first = 0.0;
  double second = 0.0;
  for (int i = centre - h; i <= centre + h; ++i) {
    const double w = std::abs(g[static_cast<std::size_t>(i)]);
    sum += w;
    first += w * (i - centre);
    second += w * (i - centre) * (i - centre);
  }
  if (sum <= 0.0) return {static_cast<double>(centre), 0.0};
  const double mean = first / sum;
  return {centre + mean, std::sqrt(std::max(0.0, second / sum - mean * mean))};
}

}  // namespace

EdgeShifts edge_shifts(const FloatImage& reference, const FloatImage& test, const EdgeOptions& options) {
  std::vector<double> shifts;
  double widening = 0.0;
  const int h = options.half_window;
  for (const bool horizontal : {true, false}) {
    const int lines = horizontal ? reference.height : reference.width;
    for (int index = 0; index < lines; ++index) {
      const auto g_ref = gradient(line(reference, index, horizontal));
      const auto g_test = gradient(line(test, index, horizontal));
      const int n = static_cast<int>(g_ref.size());
      for (int i = h + 1; i + h + 1 < n; ++i) {
        const double here = std::abs(g_ref[static_cast<std::size_t>(i)]);
        if (here < options.threshold) continue;
        if (here < std::abs(g_ref[static_cast<std::size_t>(i - 1)]) ||
            here < std::abs(g_ref[static_cast<std::size_t>(i + 1)])) {
          continue;  // not the peak of this edge
        }
        // Isolated: no other edge of either sign in the window, so the centroid
        // belongs to this one alone.
        bool isolated = true;
        for (int j = i - h; j <= i + h && isolated; ++j) {
          const double other = std::abs(g_ref[static_cast<std::size_t>(j)]);
          const bool peak = other >= std::abs(g_ref[static_cast<std::size_t>(j - 1)]) &&
                            other >= std::abs(g_ref[static_cast<std::size_t>(j + 1)]);
          if (j != i && peak && other > 0.25 * here) isolated = false;
        }
        // And the window's ends are quiet, so the whole edge is inside it.
        if (std::abs(g_ref[static_cast<std::size_t>(i - h)]) > 0.1 * here ||
            std::abs(g_ref[static_cast<std::size_t>(i + h)]) > 0.1 * here) {
          isolated = false;
        }
        if (!isolated) continue;
        const int x = horizontal ? i : index;
        const int y = horizontal ? index : i;
        if (options.where && !options.where(x, y)) continue;
        // Only edges that cross this line steeply: along a line, a shallow edge's
        // crossing moves by its displacement over the sine of its angle.
        if (x < 1 || y < 1 || x + 1 >= reference.width || y + 1 >= reference.height) continue;
        const double across = here;
        const double along = horizontal ? 0.5 * std::abs(luma(reference, x, y + 1) - luma(reference, x, y - 1))
                                        : 0.5 * std::abs(luma(reference, x + 1, y) - luma(reference, x - 1, y));
        if (along > 0.5 * across) continue;
        const EdgeProfile in_reference = profile(g_ref, i, h);
        const EdgeProfile in_test = profile(g_test, i, h);
        shifts.push_back(std::abs(in_test.position - in_reference.position));
        widening = std::max(widening, in_test.width - in_reference.width);
      }
    }
  }
  EdgeShifts result;
  result.edges = shifts.size();
  result.max_widening_px = widening;
  if (shifts.empty()) return result;
  result.max_abs_px = *std::max_element(shifts.begin(), shifts.end());
  result.median_abs_px = metrics::percentile(shifts, 50.0);
  return result;
}

}  // namespace optique::image
