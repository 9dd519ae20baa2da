#pragma once
// frames.csv: a row per (frame, node) the frame was begun on, in master-clock
// nanoseconds. The recorder hands the rows over as frames are finalized; they
// leave the protocol core as an action (FrameRows) for the shell to write.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "clock/clock.h"

namespace optique::master {

struct FrameRow {
  std::uint64_t frame = 0;
  std::string node;  // its id (from the config, not the wire)
  clock::Nanos begin_sent = 0;
  std::optional<clock::Nanos> ready_received;  // empty cells: it never got there
  std::optional<clock::Nanos> swap_sent;
  std::optional<clock::Nanos> presented;
};

struct FrameRows {
  std::vector<FrameRow> rows;
};

// The header line, and the rows' lines (each ends with a newline).
[[nodiscard]] std::string frames_csv_header();
[[nodiscard]] std::string frames_csv(std::span<const FrameRow> rows);

}  // namespace optique::master
