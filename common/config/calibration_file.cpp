#include "config/calibration_file.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "util/read_file.h"

namespace optique::config {

Result<glm::dmat3> read_calibration_homography(const std::string& path, std::uint32_t width, std::uint32_t height) {
  auto text = util::read_file(path, "calibration file");
  if (!text) return Error{text.error()};
  const auto document = nlohmann::json::parse(text.value(), nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded()) return Error{path + ": not valid JSON"};
  // Files from before calibrate wrote the image size say nothing: taken as they are.
  if (const auto image = document.find("projector"); image != document.end() && image->is_object()) {
    const auto w = image->find("width");
    const auto h = image->find("height");
    if (w != image->end() && h != image->end() && w->is_number_unsigned() && h->is_number_unsigned() &&
        (w->get<std::uint64_t>() != width || h->get<std::uint64_t>() != height)) {
      return Error{path + ": fitted for a " + std::to_string(w->get<std::uint64_t>()) + "×" +
                   std::to_string(h->get<std::uint64_t>()) + " image, but this projector is " + std::to_string(width) +
                   "×" + std::to_string(height) +
                   ": calibrate it again at the projector's resolution, or correct its width and height"};
    }
  }
  const auto found = document.find("homography");
  if (found == document.end()) return Error{path + ": no \"homography\" (write it with optique-master calibrate)"};
  const auto& rows = *found;
  if (!rows.is_array() || rows.size() != 3) return Error{path + ": homography: needs 3 rows of 3 numbers"};
  glm::dmat3 h(0.0);
  for (int r = 0; r < 3; ++r) {
    const auto& row = rows[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 3) {
      return Error{path + ": homography[" + std::to_string(r) + "]: needs 3 numbers"};
    }
    for (int c = 0; c < 3; ++c) {
      const auto& value = row[static_cast<std::size_t>(c)];
      if (!value.is_number() || !std::isfinite(value.get<double>())) {
        return Error{path + ": homography[" + std::to_string(r) + "][" + std::to_string(c) + "]: not a finite number"};
      }
      h[c][r] = value.get<double>();
    }
  }
  return h;
}

}  // namespace optique::config
