#include "tools/calibrate.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>

#include "calib/calibrate_points.h"
#include "master/run/exit_codes.h"

namespace optique::tools {

using master::kExitFailed;
using master::kExitOk;
using master::kExitUsage;
namespace {

using json = nlohmann::ordered_json;

json homography_rows(const glm::dmat3& h) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({h[0][r], h[1][r], h[2][r]});
  return rows;
}

json matrix_row_major(const glm::dmat4& m) {
  json values = json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) values.push_back(m[c][r]);
  }
  return values;
}

json output_document(const calib::Calibration& calibration, const geometry::ImageSize& image, bool robust) {
  const auto& fit = calibration.fit;
  json doc;
  doc["homography"] = homography_rows(fit.homography);
  doc["rms_px"] = fit.rms_px;
  doc["max_px"] = fit.max_px;
  doc["points"] = fit.residuals_px.size();
  doc["condition"] = fit.condition;
  doc["residuals_px"] = fit.residuals_px;
  if (fit.oblique) {
    doc["oblique_depth_factor"] = fit.oblique->factor;
    // Over the whole image: the calibration knows nothing of the screen. What a
    // node renders with is bounded over the part that lands on the screen
    // (check-config's "depth scale over the lit area"), so it can be larger.
    doc["depth_scale_whole_image"] = fit.oblique->depth_scale;
  }
  if (fit.coverage) doc["coverage"] = *fit.coverage;
  doc["warnings"] = fit.warnings;
  doc["projector"] = {{"width", image.width}, {"height", image.height}};
  if (calibration.tracker) {
    doc["plane_rms_m"] = calibration.tracker->plane_rms_m;
    doc["plane_max_m"] = calibration.tracker->plane_max_m;
    doc["tracker_to_screen"] = matrix_row_major(calibration.tracker->tracker_to_screen);
  }
  if (robust) {
    doc["inliers"] = fit.inliers;
    json outliers = json::array();
    for (const auto& o : fit.outliers) outliers.push_back({{"index", o.index}, {"residual_px", o.residual_px}});
    doc["outliers"] = outliers;
  }
  return doc;
}

// The JSON path of the first non-finite number in `value`, or "" when all are finite.
std::string first_non_finite(const json& value, const std::string& path) {
  if (value.is_number_float()) return std::isfinite(value.get<double>()) ? "" : path;
  if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (auto bad = first_non_finite(value[i], fmt::format("{}[{}]", path, i)); !bad.empty()) return bad;
    }
  }
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      if (auto bad = first_non_finite(item, path.empty() ? key : path + "." + key); !bad.empty()) return bad;
    }
  }
  return "";
}

void print_summary(const CalibrateOptions& options, const calib::Calibration& calibration, std::ostream& out) {
  const auto& fit = calibration.fit;
  const auto& h = fit.homography;
  out << fmt::format("{}: {} points → {}\n", options.points_path, fit.residuals_px.size(), options.out_path);
  out << "H (screen metres → projector pixels):\n";
  for (int r = 0; r < 3; ++r) out << fmt::format("  [{:>15.8g} {:>15.8g} {:>15.8g} ]\n", h[0][r], h[1][r], h[2][r]);
  out << fmt::format("reprojection error: rms {:.4g} px, max {:.4g} px over {} points (condition {:.3g})\n", fit.rms_px,
                     fit.max_px, fit.inliers.size(), fit.condition);
  if (options.robust) {
    out << fmt::format("robust: {} inliers, {} outliers\n", fit.inliers.size(), fit.outliers.size());
  }
  if (fit.oblique) {
    out << fmt::format(
        "oblique depth factor |a31| + |a32|: {:.4f}; depth scale over the whole image {:.4f} (rendering bounds it "
        "over the part on the screen: check-config shows that one)\n",
        fit.oblique->factor, fit.oblique->depth_scale);
  }
  if (fit.coverage) out << fmt::format("the points span {:.0f}% of the image\n", 100.0 * *fit.coverage);
  if (calibration.tracker) {
    out << fmt::format("tracker: plane rms {:.3g} m, max {:.3g} m; screen frame {}\n", calibration.tracker->plane_rms_m,
                       calibration.tracker->plane_max_m,
                       calibration.tracker->frame_given ? "as given (tracker_to_screen)" : "derived from the readings");
  }
  if (fit.warnings.empty()) {
    out << "no warnings\n";
  } else {
    for (const auto& warning : fit.warnings) out << "warning: " << warning << "\n";
  }
}

// JSON a person can read: one field per line, but arrays and objects of plain
// values (a row of H, the residuals, an outlier) on one line.
void write_readable(std::ostream& out, const json& value, int indent) {
  const auto scalar = [](const json& v) { return !v.is_array() && !v.is_object(); };
  const auto dump = [](const json& v) { return v.dump(-1, ' ', false, json::error_handler_t::replace); };
  if (scalar(value)) {
    out << dump(value);
    return;
  }
  const bool strings = value.is_array() && !value.empty() && value.front().is_string();
  const bool flat = std::all_of(value.begin(), value.end(), scalar) && !strings;
  const char* open = value.is_array() ? "[" : "{";
  const char* close = value.is_array() ? "]" : "}";
  const std::string pad = flat ? "" : std::string(static_cast<std::size_t>(indent + 2), ' ');
  out << open << (flat || value.empty() ? "" : "\n");
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (it != value.begin()) out << (flat ? ", " : ",\n");
    out << pad;
    if (value.is_object()) out << dump(it.key()) << ": ";
    write_readable(out, *it, indent + 2);
  }
  if (!flat && !value.empty()) out << "\n" << std::string(static_cast<std::size_t>(indent), ' ');
  out << close;
}

}  // namespace

int calibrate(const CalibrateOptions& options, std::ostream& out, std::ostream& err) {
  auto input = calib::read_points_file(options.points_path);
  if (!input) {
    err << input.error() << "\n";
    return kExitUsage;
  }
  calib::FitOptions fit_options;
  fit_options.robust = options.robust;
  auto calibration = calib::calibrate_points(input.value(), fit_options);
  if (!calibration) {
    err << options.points_path << ": " << calibration.error() << "\n";
    return kExitUsage;
  }
  const json doc = output_document(calibration.value(), input.value().projector, options.robust);
  // Never write NaN or ∞: nothing downstream could use it, and JSON cannot hold it.
  if (const auto bad = first_non_finite(doc, ""); !bad.empty()) {
    err << options.points_path << ": the fit is degenerate: " << bad << " is not finite; nothing written\n";
    return kExitUsage;
  }
  // Written next to the target, then renamed: a reader never sees half a file.
  const std::string temporary = options.out_path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    write_readable(file, doc, 0);
    file << "\n";
    if (!file.flush()) {
      err << options.out_path << ": cannot write the calibration file\n";
      return kExitFailed;
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, options.out_path, ec);
  if (ec) {
    err << options.out_path << ": cannot write the calibration file: " << ec.message() << "\n";
    std::filesystem::remove(temporary, ec);
    return kExitFailed;
  }
  print_summary(options, calibration.value(), out);
  return kExitOk;
}

}  // namespace optique::tools
