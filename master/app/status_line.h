#pragma once
// One live line on a terminal (frame k/N, rate, nodes up, skew, drops), redrawn in
// place. Log lines clear it first (see log pattern in cli.cpp), so the two mix.

#include <cstdio>
#include <string>

namespace optique::master {

class StatusLine {
 public:
  explicit StatusLine(bool enabled, std::FILE* stream = stderr) : enabled_(enabled), stream_(stream) {}
  void show(const std::string& text);
  void clear();
  [[nodiscard]] bool enabled() const { return enabled_; }

 private:
  bool enabled_;
  std::FILE* stream_;
  bool shown_ = false;
};

}  // namespace optique::master
