#pragma once
// `optique-master calibrate`: fits a projector's homography from a points file
// (calib/points_file.h) and writes the calibration file that configs name
// (read back by calib/calibration_file.h).

#include <iosfwd>
#include <string>

namespace optique::tools {

struct CalibrateOptions {
  std::string points_path;
  std::string out_path;
  bool robust = false;
};

// Prints a summary (H, errors, warnings) to `out` and problems to `err`.
// Returns kExitOk (warnings included), kExitUsage for bad input or a degenerate
// fit (nothing written), kExitFailed when the output cannot be written.
[[nodiscard]] int calibrate(const CalibrateOptions& options, std::ostream& out, std::ostream& err);

}  // namespace optique::tools
