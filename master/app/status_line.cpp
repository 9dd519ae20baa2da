#include "master/app/status_line.h"

namespace optique::master {

void StatusLine::show(const std::string& text) {
  if (!enabled_) return;
  std::fprintf(stream_, "\r\033[K%s", text.c_str());
  std::fflush(stream_);
  shown_ = true;
}

void StatusLine::clear() {
  if (!enabled_ || !shown_) return;
  std::fprintf(stream_, "\r\033[K");
  std::fflush(stream_);
  shown_ = false;
}

}  // namespace optique::master
