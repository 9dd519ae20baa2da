#include "master/frame_rows.h"

#include <fmt/format.h>

namespace optique::master {
namespace {

void cell(std::string& out, const std::optional<clock::Nanos>& value) {
  out += ',';
  if (value) out += fmt::to_string(*value);
}

}  // namespace

std::string frames_csv_header() { return "frame_id,node,begin_sent_ns,ready_received_ns,swap_sent_ns,presented_ns\n"; }

std::string frames_csv(std::span<const FrameRow> rows) {
  std::string out;
  for (const FrameRow& row : rows) {
    out += fmt::format("{},{},{}", row.frame, row.node, row.begin_sent);
    cell(out, row.ready_received);
    cell(out, row.swap_sent);
    cell(out, row.presented);
    out += '\n';
  }
  return out;
}

}  // namespace optique::master
