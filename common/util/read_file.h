#pragma once
// A whole file read into memory: a config, a calibration, a points file, a
// tracking replay, a journal. The error names the file, what it was meant to
// be, and the system's reason.

#include <string>

#include "util/result.h"

namespace optique::util {

// "PATH: cannot open the WHAT: REASON", or "PATH: cannot read the WHAT".
[[nodiscard]] Result<std::string> read_file(const std::string& path, const std::string& what);

}  // namespace optique::util
