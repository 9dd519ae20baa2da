#pragma once
// A bench's plot: OUT/NAME.png drawn by gnuplot from the bench's own CSV
// (OUT/NAME.csv) through scripts/plot-bench.sh, the same command that redraws the
// plots by hand. The CSV must be complete and closed before this runs.

#include <cstdlib>
#include <iostream>
#include <string>

namespace optique::bench {

[[nodiscard]] inline bool draw_plot(const std::string& out, const std::string& name) {
  const auto quoted = [](const std::string& text) {
    std::string q = "'";
    for (const char c : text) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  const std::string command =
      quoted(std::string(OPTIQUE_SOURCE_DIR) + "/scripts/plot-bench.sh") + " " + quoted(out) + " " + quoted(name);
  if (std::system(command.c_str()) != 0) {
    std::cerr << "the plot " << out << "/" << name << ".png was not drawn (" << command
              << " failed, see above); the tables and the CSV are written\n";
    return false;
  }
  return true;
}

}  // namespace optique::bench
