#pragma once
// What the end of a run says: one summary line (the frame rate against the
// target, the share of frames every projector showed, the barrier and the
// skew), and whether the run failed because too few frames were shown.

#include <optional>
#include <string>

#include "optique/report.pb.h"

namespace optique::master {

// The share of the run's frames that every projector showed (0 with no frames):
// of `frames`, all but `with_missing_node`; or of a report's.
[[nodiscard]] double shown_by_all_share(std::uint64_t frames, std::uint64_t with_missing_node);
[[nodiscard]] double shown_by_all_share(const report::RunReport& report);

// Why the run failed for what it showed, or nothing: with `min_presented`,
// fewer than that share shown by every projector; without, no frame shown by
// any. A run that began no frame is judged elsewhere (it failed to start, or
// was stopped before it could).
[[nodiscard]] std::optional<std::string> too_few_shown(const report::RunReport& report,
                                                       std::optional<double> min_presented);

// "300 frames at 59.9 of 60 Hz; 100.0 % shown by every projector; barrier
// round median 140 µs p99 260 µs; present skew …; 0 frame(s) with a node missing"
[[nodiscard]] std::string summary_line(const report::RunReport& report);

}  // namespace optique::master
