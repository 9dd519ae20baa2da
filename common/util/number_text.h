#pragma once
// Numbers in messages, as a person would write them: shortest form, no padding
// ("2.2", "1e-06", "inf", "nan").

#include <sstream>
#include <string>

namespace optique::util {

[[nodiscard]] inline std::string number_text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace optique::util
